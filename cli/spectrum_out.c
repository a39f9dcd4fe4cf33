/* spectrum_out.c — a computed spectrum as HDF5 (one group per curve), CSV
 * (long format, one row per point), gnuplot charts, JSON and text.  Files
 * are written to a temporary name and renamed on success, and hold no
 * timings or dates (their provenance has no `created`, and its command
 * leaves out -o, --plot, --json, --threads, --resume and --stop-after), so
 * equal sweeps give byte-identical files (docs/formats.md).  Every write
 * is checked: a failure is reported with the system's reason and leaves no
 * file (the journal stays, so the sweep can be resumed). */
#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "pd_h5.h"
#include "pd_output.h"
#include "pd_plot.h"
#include "pd_spectrum.h"

/* A per-point column of the output. */
typedef struct col_def {
    const char *name, *units;
    size_t off;
    int is_long;
} col_def;

#define DCOL(name, units, field)                                                                   \
    {                                                                                              \
        name, units, offsetof(pd_spec_row, field), 0                                               \
    }
#define LCOL(name, field)                                                                          \
    {                                                                                              \
        name, "1", offsetof(pd_spec_row, field), 1                                                 \
    }
static const col_def point_cols[] = {
    DCOL("Pi2", "1", c.Pi2), DCOL("T0", "s", T0), DCOL("Pi1", "1", Pi1), DCOL("umax", "m", umax),
    DCOL("umax_free", "m", umax_free), DCOL("gamma", "1", gamma), DCOL("chi", "1", chi),
    DCOL("u_toward", "m", u_toward), DCOL("u_away", "m", u_away), LCOL("impacts", impacts),
    DCOL("contact_time", "s", contact_time), DCOL("first_impact", "s", first_impact),
    LCOL("steps", steps), DCOL("dt", "s", dt), DCOL("tend", "s", tend),
    /* a yielding sweep's, last (ncols) */
    DCOL("ductility", "1", ductility), DCOL("ductility_free", "1", ductility_free),
    DCOL("residual_uy", "1", residual_uy)};
enum { NCOLS = sizeof point_cols / sizeof point_cols[0], NYIELD_COLS = 3 };

/* The columns of s's points: the yielding ones for a yielding sweep only. */
static int ncols(const pd_spectrum *s)
{
    return pd_osc_yields(&s->base) ? NCOLS : NCOLS - NYIELD_COLS;
}

/* The value of column d in row r. */
static double col_value(const pd_spec_row *r, const col_def *d)
{
    const char *p = (const char *)r + d->off;
    if (d->is_long) {
        long v;
        memcpy(&v, p, sizeof v);
        return (double)v;
    }
    double x;
    memcpy(&x, p, sizeof x);
    return x;
}

/* Does path end with suffix? */
static int ends_with(const char *path, const char *suffix)
{
    size_t n = strlen(path), k = strlen(suffix);
    return n > k && !strcmp(path + n - k, suffix);
}

/* How dt was chosen, in words. */
static void dt_rule(const pd_spectrum *s, char *buf, size_t cap)
{
    if (s->dt_per_Tp > 0.0)
        snprintf(buf, cap, "Tp/%.17g", s->dt_per_Tp);
    else if ((s->opts.dt > 0.0))
        snprintf(buf, cap, "%.17g s", s->opts.dt);
    else
        snprintf(buf, cap, "min(Tp,T0)/2000");
}

/* ---- HDF5 --------------------------------------------------------------- */

/* A 1-D double dataset with a "units" attribute. */
static int h5_dataset(hid_t grp, hid_t dcpl, const char *name, const char *units, const double *x,
                      long n)
{
    hsize_t dims[1] = {(hsize_t)n};
    hid_t space = H5Screate_simple(1, dims, NULL), ds = -1;
    int rc = -1;
    if (space < 0)
        return -1;
    ds = H5Dcreate2(grp, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds >= 0 && H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x) >= 0)
        rc = pd_h5_attr(ds, "units", units, 0.0) || /* along Pi2 (the first column) */
             (strcmp(name, "Pi2") ? pd_h5_dims(ds, "Pi2") : pd_h5_coord(ds, "Pi2"));
    if (pd_h5_close_id(&ds) || H5Sclose(space) < 0)
        rc = -1;
    return rc;
}

/* The curve's parameters as attributes of its group. */
static int h5_curve_attrs(hid_t g, const pd_spectrum *s, const pd_spec_row *r, long curve)
{
    char label[256];
    pd_spec_curve_label(s, curve, label, sizeof label);
    return pd_h5_attr(g, "label", label, 0) ||
           pd_h5_attr(g, "pulse", pd_osc_excitation_name(&r->c), 0) ||
           pd_h5_attr(g, "dir", pd_dir_name(r->c.dir), 0) ||
           pd_h5_attr(g, "method", pd_method_name(s->opts.method), 0) ||
           pd_h5_num(g, "ap", r->c.ap, "m/s^2") || pd_h5_num(g, "Tp", r->c.Tp, "s") ||
           pd_h5_num(g, "Pi3", r->c.Pi3, "1") || pd_h5_num(g, "gap", r->gap, "m") ||
           pd_h5_num(g, "eps", r->c.eps, "1") || pd_h5_num(g, "xi", r->c.xi, "1") ||
           (pd_osc_yields(&r->c) &&
            (pd_h5_num(g, "Piy", r->c.Piy, "1") || pd_h5_num(g, "alpha", r->c.alpha, "1") ||
             pd_h5_num(g, "uy", pd_osc_uy(&r->c), "m")));
}

/* Group curve_NNNN: attributes and one dataset per column. */
static int h5_curve(hid_t file, hid_t gcpl, hid_t dcpl, const pd_spectrum *s,
                    const pd_spec_row *rows, long curve, double *buf)
{
    char name[32];
    const pd_spec_row *r = rows + curve * s->npi2;
    snprintf(name, sizeof name, "curve_%04ld", curve);
    hid_t g = H5Gcreate2(file, name, H5P_DEFAULT, gcpl, H5P_DEFAULT);
    int rc = g < 0 ? -1 : h5_curve_attrs(g, s, r, curve);
    for (int k = 0; k < ncols(s) && !rc; k++) {
        for (int j = 0; j < s->npi2; j++)
            buf[j] = col_value(&r[j], &point_cols[k]);
        rc = h5_dataset(g, dcpl, point_cols[k].name, point_cols[k].units, buf, s->npi2);
    }
    if (g >= 0 && H5Gclose(g) < 0)
        rc = -1;
    return rc;
}

/* The provenance and the sweep's common parameters as root attributes. */
static int h5_root_attrs(hid_t file, const pd_spectrum *s)
{
    char rule[64];
    pd_provenance p;
    pd_provenance_now(&p, PD_FORMAT_SPECTRUM);
    dt_rule(s, rule, sizeof rule);
    return pd_provenance_h5(file, &p) ||
           pd_h5_attr(file, "method", pd_method_name(s->opts.method), 0) ||
           pd_h5_attr(file, "Pi2_spacing", s->linear ? "linear" : "log", 0) ||
           pd_h5_num(file, "Pi2_min", s->pi2_min, "1") ||
           pd_h5_num(file, "Pi2_max", s->pi2_max, "1") || pd_h5_num(file, "Pi2_n", s->npi2, "1") ||
           pd_h5_num(file, "Tp", s->base.Tp, "s") || pd_h5_attr(file, "dt", rule, 0) ||
           pd_h5_num(file, "theta", s->opts.theta, "1") ||
           pd_h5_num(file, "curves", (double)pd_spec_curves(s), "1") ||
           pd_h5_num(file, "points", (double)pd_spec_points(s), "1");
}

/* The whole spectrum into an HDF5 file: 0 or an errno. */
static int write_hdf5(const char *path, const pd_spectrum *s, const pd_spec_row *rows)
{
    hid_t fcpl = pd_h5_untimed(H5P_FILE_CREATE), gcpl = pd_h5_untimed(H5P_GROUP_CREATE);
    hid_t dcpl = pd_h5_untimed(H5P_DATASET_CREATE), file = -1;
    double *buf = malloc((size_t)s->npi2 * sizeof *buf);
    int rc = -1, failure = 0, e = ENOMEM;
    if (fcpl >= 0 && gcpl >= 0 && dcpl >= 0 && buf &&
        (file = pd_h5_create(path, fcpl, &failure)) >= 0) {
        rc = h5_root_attrs(file, s);
        for (long c = 0; c < pd_spec_curves(s) && !rc && !failure; c++)
            rc = h5_curve(file, gcpl, dcpl, s, rows, c, buf);
        e = pd_h5_close(&file, &failure);
    } else if (failure)
        e = failure;
    free(buf);
    pd_h5_close_id(&fcpl);
    pd_h5_close_id(&gcpl);
    pd_h5_close_id(&dcpl);
    return e ? e : rc ? EIO : 0;
}

/* ---- CSV ---------------------------------------------------------------- */

/* The curve columns of the CSV (before the point columns), and their units. */
static const char *const csv_curve_cols[][2] = {{"pulse", "1"},  {"dir", "1"}, {"method", "1"},
                                                {"ap", "m/s^2"}, {"Tp", "s"},  {"Pi3", "1"},
                                                {"gap", "m"},    {"eps", "1"}, {"xi", "1"}};
enum { NCURVE_COLS = sizeof csv_curve_cols / sizeof csv_curve_cols[0] };

/* The provenance and "# name = value" lines, "# units = ..." (one per
 * column), the header row, one row per point: 0 or an errno. */
static int write_csv(const char *path, const pd_spectrum *s, const pd_spec_row *rows)
{
    char rule[64];
    pd_csv f;
    pd_provenance prov;
    if (pd_csv_open(&f, path))
        return f.failure;
    pd_provenance_now(&prov, PD_FORMAT_SPECTRUM);
    pd_provenance_csv(&f, &prov);
    dt_rule(s, rule, sizeof rule);
    pd_csv_printf(&f, "# method = %s\n# Pi2 = %.17g:%.17g:%d %s\n# dt = %s\n# theta = %.17g\n",
                  pd_method_name(s->opts.method), s->pi2_min, s->pi2_max, s->npi2,
                  s->linear ? "linear" : "log", rule, s->opts.theta);
    pd_csv_printf(&f, "# units = ");
    for (int k = 0; k < NCURVE_COLS; k++)
        pd_csv_printf(&f, "%s%s", k ? "," : "", csv_curve_cols[k][1]);
    for (int k = 0; k < ncols(s); k++)
        pd_csv_printf(&f, ",%s", point_cols[k].units);
    pd_csv_printf(&f, "\n");
    for (int k = 0; k < NCURVE_COLS; k++)
        pd_csv_printf(&f, "%s%s", k ? "," : "", csv_curve_cols[k][0]);
    for (int k = 0; k < ncols(s); k++)
        pd_csv_printf(&f, ",%s", point_cols[k].name);
    pd_csv_printf(&f, "\n");
    for (long p = 0; p < pd_spec_points(s) && !f.failure; p++) {
        const pd_spec_row *r = &rows[p];
        pd_csv_printf(&f, "%s,%s,%s,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g",
                      pd_osc_excitation_name(&r->c), pd_dir_name(r->c.dir),
                      pd_method_name(s->opts.method), r->c.ap, r->c.Tp, r->c.Pi3, r->gap, r->c.eps,
                      r->c.xi);
        for (int k = 0; k < ncols(s); k++)
            pd_csv_printf(&f, ",%.17g", col_value(r, &point_cols[k]));
        pd_csv_printf(&f, "\n");
    }
    return pd_csv_close(&f);
}

int pd_spec_write(const char *path, const pd_spectrum *s, const pd_spec_row *rows, pd_err *err)
{
    pd_outfile o;
    int h5 = ends_with(path, ".h5") || ends_with(path, ".hdf5"), rc, e;
    if (!h5 && !ends_with(path, ".csv"))
        return pd_err_set(err, PD_EINVAL, "-o %s: the file name must end in .h5, .hdf5 or .csv",
                          path);
    if ((rc = pd_outfile_begin(&o, "-o", path, err)))
        return rc;
    if ((e = h5 ? write_hdf5(o.tmp, s, rows) : write_csv(o.tmp, s, rows))) {
        pd_outfile_abort(&o);
        return pd_outfile_error(&o, e, err);
    }
    return pd_outfile_commit(&o, err);
}

/* ---- charts ------------------------------------------------------------- */

/* The parameters every curve shares, for a chart title (UTF-8: the charts
 * show names as they are, pd_plot_literal); nrec > 0: a suite's records. */
static void common_title(const pd_spectrum *s, int nrec, char *buf, size_t cap)
{
    size_t n = (size_t)snprintf(buf, cap, "spectra (%s", pd_method_name(s->opts.method));
#define ADD(...) (n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, __VA_ARGS__))
    if (nrec > 0)
        ADD(", a suite of %d records", nrec);
    else if (s->npulse == 1)
        ADD(", %s", s->base.record ? s->base.record->name : pd_pulse_name(s->pulse[0]));
    if (s->ndir == 1)
        ADD(nrec > 0 ? ", %s" : " %s", pd_dir_name(s->dir[0]));
    if (s->nsize == 1)
        ADD(", %s = %g%s", s->size_is_gap ? "gap" : "\u03a0\u2083", s->size[0],
            s->size_is_gap ? " m" : "");
    if (s->neps == 1)
        ADD(", \u03b5 = %g", s->eps[0]);
    if (s->nxi == 1)
        ADD(", \u03be = %g", s->xi[0]);
    ADD(")");
#undef ADD
}

/* A curve's key from its label (pd_spec_curve_label: words and key=value
 * pairs): "sine normal ap=3 Pi3=0.05 eps=0.5" as "sine normal, ap = 3 m/s²,
 * Π₃ = 0.05, ε = 0.5". */
static void curve_key(const char *label, char *buf, size_t cap)
{
    static const struct {
        const char *key, *shown, *units;
    } names[] = {{"ap", "ap", " m/s\u00b2"},
                 {"xi", "\u03be", ""},
                 {"Pi3", "\u03a0\u2083", ""},
                 {"gap", "gap", " m"},
                 {"eps", "\u03b5", ""}};
    size_t n = 0;
    int pairs = 0;
    buf[0] = '\0';
    for (const char *w = label; *w;) {
        size_t len = strcspn(w, " ");
        const char *eq = memchr(w, '=', len);
        const char *sep = pairs || (eq && n) ? ", " : n ? " " : "";
        int k = 0;
        while (eq && k < 5 &&
               (strlen(names[k].key) != (size_t)(eq - w) ||
                strncmp(w, names[k].key, (size_t)(eq - w))))
            k++;
        if (eq && k < 5)
            n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, "%s%s = %.*s%s", sep,
                                  names[k].shown, (int)(w + len - eq - 1), eq + 1, names[k].units);
        else
            n += (size_t)snprintf(buf + n, n < cap ? cap - n : 0, "%s%.*s", sep, (int)len, w);
        pairs |= eq != NULL;
        w += len;
        w += *w == ' ';
    }
}

/* The chart of the curves cv on log axes against T0 or Pi2, titled with
 * what the curves share (nrec > 0: a suite's). */
static int draw(const char *png, const pd_spectrum *s, int nrec, const pd_curve *cv, long ncurves,
                int use_T0, const char *ylabel, int logy, pd_err *err)
{
    char title[256];
    common_title(s, nrec, title, sizeof title);
    pd_chart ch = {.title = title,
                   .xlabel = use_T0 ? "T_0 [s]" : "{/Symbol P}_2 = T_p / T_0",
                   .ylabel = ylabel,
                   .logx = 1,
                   .logy = logy,
                   .ncurves = (int)ncurves,
                   .curves = cv,
                   .vline = NAN};
    return pd_plot(png, &ch, err);
}

/* One chart, one curve per spectrum curve; y = f(row) scaled; x = T0 or Pi2. */
static int chart(const char *png, const pd_spectrum *s, const pd_spec_row *rows, int use_T0,
                 size_t yoff, double yscale, const char *ylabel, int logy, pd_err *err)
{
    long nc = pd_spec_curves(s), np = pd_spec_points(s);
    double *x = malloc((size_t)np * sizeof *x), *y = malloc((size_t)np * sizeof *y);
    pd_curve *cv = malloc((size_t)nc * sizeof *cv);
    char *labels = malloc((size_t)nc * 128);
    int rc;
    if (!x || !y || !cv || !labels) {
        rc = pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
        goto done;
    }
    for (long p = 0; p < np; p++) {
        x[p] = use_T0 ? rows[p].T0 : rows[p].c.Pi2;
        memcpy(&y[p], (const char *)&rows[p] + yoff, sizeof y[p]);
        y[p] *= yscale;
    }
    for (long c = 0; c < nc; c++) {
        char label[128];
        pd_spec_curve_label(s, c, label, sizeof label);
        curve_key(label, labels + 128 * c, 128);
        cv[c] = (pd_curve){
            .label = labels + 128 * c, .n = s->npi2, .x = x + c * s->npi2, .y = y + c * s->npi2};
    }
    rc = draw(png, s, 0, cv, nc, use_T0, ylabel, logy, err);
done:
    free(x);
    free(y);
    free(cv);
    free(labels);
    return rc;
}

/* A suite's chart: each record's curves faint, then the mean of every
 * curve over the records; y = f(row) scaled, x = T0 or Pi2. */
static int chart_suite(const char *png, const pd_spectrum *s, int nrec, const pd_spec_row *rows,
                       const pd_spec_row *mean, int use_T0, size_t yoff, double yscale,
                       const char *ylabel, int logy, pd_err *err)
{
    long nc = pd_spec_curves(s), np = pd_spec_points(s), nall = (long)(nrec + 1) * np;
    long ncurves = (long)(nrec + 1) * nc;
    double *x = malloc((size_t)nall * sizeof *x), *y = malloc((size_t)nall * sizeof *y);
    pd_curve *cv = malloc((size_t)ncurves * sizeof *cv);
    char *labels = malloc((size_t)nc * 160), faint[64];
    int rc;
    if (!x || !y || !cv || !labels) {
        rc = pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
        goto done;
    }
    for (long p = 0; p < nall; p++) { /* the records' rows, then the mean's */
        const pd_spec_row *r = p < (long)nrec * np ? &rows[p] : &mean[p - (long)nrec * np];
        x[p] = use_T0 ? r->T0 : r->c.Pi2;
        memcpy(&y[p], (const char *)r + yoff, sizeof y[p]);
        y[p] *= yscale;
    }
    snprintf(faint, sizeof faint, "each of the %d records", nrec);
    for (int k = 0; k < nrec; k++)
        for (long c = 0; c < nc; c++) {
            long off = (long)k * np + c * s->npi2;
            cv[k * nc + c] = (pd_curve){.label = k == 0 && c == 0 ? faint : "",
                                        .n = s->npi2,
                                        .x = x + off,
                                        .y = y + off,
                                        .style = PD_CURVE_FAINT};
        }
    for (long c = 0; c < nc; c++) {
        char label[128], key[128];
        long off = (long)nrec * np + c * s->npi2;
        pd_spec_curve_label(s, c, label, sizeof label);
        curve_key(label, key, sizeof key);
        snprintf(labels + 160 * c, 160, "mean%s%s", nc > 1 ? ": " : "", nc > 1 ? key : "");
        cv[(long)nrec * nc + c] =
            (pd_curve){.label = labels + 160 * c, .n = s->npi2, .x = x + off, .y = y + off};
    }
    rc = draw(png, s, nrec, cv, ncurves, use_T0, ylabel, logy, err);
done:
    free(x);
    free(y);
    free(cv);
    free(labels);
    return rc;
}

int pd_spec_plot_suite(const char *png, const pd_spectrum *s, int nrec, const pd_spec_row *rows,
                       const pd_spec_row *mean, int use_T0, pd_err *err)
{
    char other[4200];
    size_t len = strlen(png);
    int rc = chart_suite(png, s, nrec, rows, mean, use_T0, offsetof(pd_spec_row, Pi1), 1.0,
                         "{/Symbol P}_1 = u_{max} {/Symbol w}_p^2 / a_p", 1, err);
    snprintf(other, sizeof other, "%.*s-gamma.png", (int)(len - 4), png);
    if (!rc)
        rc = chart_suite(other, s, nrec, rows, mean, use_T0, offsetof(pd_spec_row, gamma), 1.0,
                         "{/Symbol g} = u_{max} / u_{max,free}", 0, err);
    snprintf(other, sizeof other, "%.*s-dim.png", (int)(len - 4), png);
    if (!rc)
        rc = chart_suite(other, s, nrec, rows, mean, use_T0, offsetof(pd_spec_row, umax), 100.0,
                         "u_{max} [cm]", 1, err);
    return rc;
}

int pd_spec_plot(const char *png, const pd_spectrum *s, const pd_spec_row *rows, pd_err *err)
{
    char other[4200];
    size_t len = strlen(png);
    int rc = chart(png, s, rows, 0, offsetof(pd_spec_row, Pi1), 1.0,
                   "{/Symbol P}_1 = u_{max} {/Symbol w}_p^2 / a_p", 1, err);
    snprintf(other, sizeof other, "%.*s-gamma.png", (int)(len - 4), png);
    if (!rc)
        rc = chart(other, s, rows, 0, offsetof(pd_spec_row, gamma), 1.0,
                   "{/Symbol g} = u_{max} / u_{max,free}", 0, err);
    snprintf(other, sizeof other, "%.*s-dim.png", (int)(len - 4), png);
    if (!rc && s->dimensional)
        rc = chart(other, s, rows, 1, offsetof(pd_spec_row, umax), 100.0, "u_{max} [cm]", 1, err);
    return rc;
}

/* ---- JSON and text ------------------------------------------------------ */

/* One point as a JSON object (the SPEC keys first). */
void pd_spec_json_point(pd_json *js, const pd_spectrum *s, const pd_spec_row *r)
{
    pd_json_begin_object(js, NULL);
    pd_json_str(js, "pulse", pd_osc_excitation_name(&r->c));
    pd_json_str(js, "dir", pd_dir_name(r->c.dir));
    pd_json_num(js, "Pi2", r->c.Pi2);
    pd_json_num(js, "Pi3", r->c.Pi3);
    pd_json_num(js, "eps", r->c.eps);
    pd_json_num(js, "xi", r->c.xi);
    pd_json_num(js, "Pi1", r->Pi1);
    pd_json_num(js, "umax_free", r->umax_free);
    pd_json_num(js, "gamma", r->gamma);
    pd_json_num(js, "chi", r->chi);
    pd_json_int(js, "impacts", r->impacts);
    pd_json_str(js, "method", pd_method_name(s->opts.method));
    pd_json_int(js, "curve", r->curve);
    pd_json_num(js, "umax", r->umax);
    pd_json_num(js, "u_toward", r->u_toward);
    pd_json_num(js, "u_away", r->u_away);
    pd_json_num(js, "contact_time", r->contact_time);
    pd_json_num(js, "first_impact", r->first_impact);
    pd_json_num(js, "ap", r->c.ap);
    pd_json_num(js, "Tp", r->c.Tp);
    pd_json_num(js, "T0", r->T0);
    pd_json_num(js, "gap", r->gap);
    pd_json_num(js, "dt", r->dt);
    pd_json_num(js, "tend", r->tend);
    pd_json_int(js, "steps", r->steps);
    pd_json_num(js, "cpu_s", r->cpu_s);
    if (pd_osc_yields(&r->c)) { /* a yielding sweep */
        pd_json_num(js, "Piy", r->c.Piy);
        pd_json_num(js, "alpha", r->c.alpha);
        pd_json_num(js, "uy", pd_osc_uy(&r->c));
        pd_json_num(js, "ductility", r->ductility);
        pd_json_num(js, "ductility_free", r->ductility_free);
        pd_json_num(js, "residual_uy", r->residual_uy);
    }
    pd_json_end_object(js);
}

void pd_spec_print_json(const pd_spectrum *s, const pd_spec_row *rows, const pd_spec_totals *t)
{
    pd_json js;
    pd_json_init(&js, stdout);
    pd_json_begin_object(&js, NULL);
    pd_json_begin_array(&js, "points");
    for (long p = 0; p < pd_spec_points(s); p++)
        pd_spec_json_point(&js, s, &rows[p]);
    pd_json_end_array(&js);
    pd_json_str(&js, "method", pd_method_name(s->opts.method));
    pd_json_str(&js, "method_by", t->method_by);
    pd_json_int(&js, "curves", pd_spec_curves(s));
    pd_json_int(&js, "runs", t->runs);
    pd_json_int(&js, "twins", pd_spec_twins(s));
    pd_json_int(&js, "resumed", t->resumed);
    pd_json_num(&js, "steps", t->steps);
    pd_json_int(&js, "threads", t->threads);
    pd_json_int(&js, "ranks", t->ranks);
    pd_json_num(&js, "cpu_s", t->cpu_s);
    pd_json_num(&js, "wall_s", t->wall_s);
    pd_json_end_object(&js);
    pd_json_finish(&js);
}

/* One curve in a line: its peak Pi1, the range of gamma, impacts. */
static void text_curve(const pd_spectrum *s, const pd_spec_row *r, long curve)
{
    char label[128];
    int jmax = 0, hit = 0;
    double gmin = HUGE_VAL, gmax = -HUGE_VAL;
    for (int j = 0; j < s->npi2; j++) {
        jmax = r[j].Pi1 > r[jmax].Pi1 ? j : jmax;
        gmin = fmin(gmin, r[j].gamma);
        gmax = fmax(gmax, r[j].gamma);
        hit += r[j].impacts > 0;
    }
    pd_spec_curve_label(s, curve, label, sizeof label);
    printf("  %-36s %10.4g %10.4g %9.4g %9.4g %7d/%d", label, r[jmax].Pi1, r[jmax].c.Pi2, gmin,
           gmax, hit, s->npi2);
    if (pd_osc_yields(&s->base)) { /* the peak ductility and where */
        int jmu = 0;
        for (int j = 0; j < s->npi2; j++)
            jmu = r[j].ductility > r[jmu].ductility ? j : jmu;
        printf(" %9.4g %9.4g", r[jmu].ductility, r[jmu].c.Pi2);
    }
    printf("\n");
}

void pd_spec_print_text(const pd_spectrum *s, const pd_spec_row *rows, const pd_spec_totals *t)
{
    char rule[64];
    dt_rule(s, rule, sizeof rule);
    printf("pounding spectra: %ld curves x %d Pi2 in [%g, %g] (%s), %s, dt = %s\n",
           pd_spec_curves(s), s->npi2, s->pi2_min, s->pi2_max, s->linear ? "linear" : "log",
           pd_method_name(s->opts.method), rule);
    if (pd_osc_yields(&s->base))
        printf("  yielding: Piy = %g (uy = %g m at ap = %g m/s^2), alpha = %g\n", s->base.Piy,
               pd_osc_uy(&s->base), s->base.ap, s->base.alpha);
    printf("  %-36s %10s %10s %9s %9s %9s%s\n", "curve", "max Pi1", "at Pi2", "min gamma",
           "max gamma", "impacting", pd_osc_yields(&s->base) ? "    max mu    at Pi2" : "");
    for (long c = 0; c < pd_spec_curves(s); c++)
        text_curve(s, rows + c * s->npi2, c);
    if (!strcmp(t->method_by, "default") && pd_osc_yields(&s->base) &&
        !pd_osc_yield_exact(&s->base))
        printf("  method %s: the exact reference does not model this yielding spring (xi >= "
               "sqrt(alpha) > 0)\n",
               pd_method_name(s->opts.method));
    else if (!strcmp(t->method_by, "default"))
        printf("  method %s: the default for one oscillator (%s); --method "
               "moreau|event|penalty|newmark "
               "chooses\n",
               pd_method_name(s->opts.method),
               s->opts.method == PD_METHOD_EVENT ? "exact and fastest"
                                                 : "the exact reference's scan is over budget");
    else
        printf("  method %s (%s)\n", pd_method_name(s->opts.method), t->method_by);
    printf("  %ld runs (%ld no-wall twins shared across gaps and eps, %ld resumed), "
           "cpu %.3g s, wall %.3g s, %d thread(s) x %d rank(s)\n",
           t->runs, pd_spec_twins(s), t->resumed, t->cpu_s, t->wall_s, t->threads, t->ranks);
}
