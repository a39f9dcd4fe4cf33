/* scene_out.c — (cli) a scene run's histories streamed to HDF5 or CSV while
 * it runs, so memory stays bounded whatever the run length, with every
 * input and result added at the end; written under a temporary name and
 * renamed on success.  Also the decimated copy that --plot draws.
 *
 * HDF5:  the provenance (format "pound simulate scene 1") and the run as
 *        attributes of the root; /t [s]; /structures/NAME/{x, v} (rows x
 *        storeys, m and m/s) with the structure and its results as
 *        attributes (a yielding structure also up, m: its storeys' plastic
 *        offsets), a (rows x storeys, m/s^2: the floors' absolute
 *        accelerations); /contacts/K/{gap, impulse} (m, N s), force (N: the
 *        penalty methods' element force) with the contact and its results as
 *        attributes.
 * CSV:   '#' lines with the provenance, "# units = ..." (one per column), a
 *        header row, one row per sample (t, NAME.x1.., NAME.v1.., cK.gap..,
 *        cK.impulse.., then NAME.up1.. of the yielding structures, NAME.a1..,
 *        then cK.force.. of the penalty methods), '#' lines
 *        with the run and its results at the end.
 * docs/formats.md describes both.
 * Every write is checked; the first failure stops the run and is reported
 * with the system's reason, and the temporary file is removed. */
#include <errno.h>
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_h5.h"
#include "pd_output.h"
#include "pd_scene_out.h"

#define OUT_BUFFER_DOUBLES (1L << 22) /* row buffer, doubles (32 MiB) */

struct pd_scene_writer {
    const pd_scene *sc;
    pd_outfile out;
    int hdf5, failure; /* failure: errno of the first failed write, 0 if none */
    long every, seen, rows;
    double *imp; /* m: impulses since the last recorded row */
    /* rows waiting to be written: t, x (n), v (n), gap (m), impulse (m), then
     * up (nup: the storeys of the yielding structures), a (n), force (m when
     * forces) per row */
    long cap, nbuf;
    double *buf, *col;      /* cap rows x width; col: one block of a structure */
    int width, nup, forces; /* forces: the contacts' element forces are written */
    hid_t file, ds_t;
    hid_t *ds_x, *ds_v, *ds_g, *ds_p, *ds_up, *ds_a, *ds_f;
    pd_csv csv;
    pd_provenance prov;
};

/* Whether structure s has a yielding storey (its offsets are written). */
static int yields(const pd_scene *sc, int s)
{
    return sc->st[s].uy != NULL;
}

/* Does path end with suffix? */
static int ends_with(const char *path, const char *suffix)
{
    size_t n = strlen(path), k = strlen(suffix);
    return n > k && !strcmp(path + n - k, suffix);
}

/* The first failure, or the address space running short for the library
 * (pd_h5_headroom): 1 when the writer must stop. */
static int short_of_memory(pd_scene_writer *w)
{
    if (!w->failure)
        w->failure = pd_h5_headroom(PD_H5_HEADROOM);
    return w->failure != 0;
}

/* The groups and extendible datasets of every structure and contact: 0 or
 * an errno. */
static int h5_open(pd_scene_writer *w)
{
    const pd_scene *sc = w->sc;
    char name[96];
    if ((w->file = pd_h5_create(w->out.tmp, H5P_DEFAULT, &w->failure)) < 0)
        return w->failure;
    if (pd_provenance_h5(w->file, &w->prov))
        return w->failure ? w->failure : pd_h5_errno();
    hid_t gs = H5Gcreate2(w->file, "structures", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    hid_t gc = H5Gcreate2(w->file, "contacts", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    /* the dimensions: t at the root, storey (floors 1..S) in each structure */
    int rc = gs < 0 || gc < 0 || (w->ds_t = pd_h5_extendible_coord(w->file, "t", w->cap, "s")) < 0;
    for (int s = 0; s < sc->nstruct && !rc && !short_of_memory(w); s++) {
        hid_t g = H5Gcreate2(gs, sc->st[s].name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        /* t in the group too (a hard link to /t: no copy), so that a reader
         * of the group alone (xarray's group=) finds its coordinate */
        rc = g < 0 || H5Lcreate_hard(w->file, "/t", g, "t", H5P_DEFAULT, H5P_DEFAULT) < 0 ||
             pd_h5_index(g, "storey", sc->st[s].storeys, 1, "1") ||
             (w->ds_x[s] = pd_h5_extendible(g, "x", H5T_NATIVE_DOUBLE, sc->st[s].storeys, w->cap,
                                            "m")) < 0 ||
             (w->ds_v[s] = pd_h5_extendible(g, "v", H5T_NATIVE_DOUBLE, sc->st[s].storeys, w->cap,
                                            "m/s")) < 0 ||
             (yields(sc, s) &&
              (w->ds_up[s] = pd_h5_extendible(g, "up", H5T_NATIVE_DOUBLE, sc->st[s].storeys, w->cap,
                                              "m")) < 0) ||
             (w->ds_a[s] = pd_h5_extendible(g, "a", H5T_NATIVE_DOUBLE, sc->st[s].storeys, w->cap,
                                            "m/s^2")) < 0;
        if (g >= 0 && H5Gclose(g) < 0)
            rc = 1;
    }
    for (int a = 0; a < sc->ncontact && !rc && !short_of_memory(w); a++) {
        snprintf(name, sizeof name, "%d", a);
        hid_t g = H5Gcreate2(gc, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        rc = g < 0 || H5Lcreate_hard(w->file, "/t", g, "t", H5P_DEFAULT, H5P_DEFAULT) < 0 ||
             (w->ds_g[a] = pd_h5_extendible(g, "gap", H5T_NATIVE_DOUBLE, 0, w->cap, "m")) < 0 ||
             (w->ds_p[a] = pd_h5_extendible(g, "impulse", H5T_NATIVE_DOUBLE, 0, w->cap, "N s")) <
                 0 ||
             (w->forces &&
              (w->ds_f[a] = pd_h5_extendible(g, "force", H5T_NATIVE_DOUBLE, 0, w->cap, "N")) < 0);
        if (g >= 0 && H5Gclose(g) < 0)
            rc = 1;
    }
    /* Every dataset named along its dimensions (docs/formats.md, "dims"), once
     * all exist: each attachment rewrites t's list of the datasets attached
     * to it, and rewritten back to back the old lists' space is reused (10,000
     * attachments interleaved with the creations left 245 MB of dead lists).
     * A new dataset is attached here too. */
    for (int s = 0; s < sc->nstruct && !rc && !short_of_memory(w); s++)
        rc = pd_h5_dims(w->ds_x[s], "t,storey") || pd_h5_dims(w->ds_v[s], "t,storey") ||
             (yields(sc, s) && pd_h5_dims(w->ds_up[s], "t,storey")) ||
             pd_h5_dims(w->ds_a[s], "t,storey");
    for (int a = 0; a < sc->ncontact && !rc && !short_of_memory(w); a++)
        rc = pd_h5_dims(w->ds_g[a], "t") || pd_h5_dims(w->ds_p[a], "t") ||
             (w->forces && pd_h5_dims(w->ds_f[a], "t"));
    if (gs >= 0 && H5Gclose(gs) < 0)
        rc = 1;
    if (gc >= 0 && H5Gclose(gc) < 0)
        rc = 1;
    return w->failure ? w->failure : rc ? pd_h5_errno() : 0;
}

/* The CSV's provenance, units and header rows: 0 or an errno. */
static int csv_open(pd_scene_writer *w)
{
    const pd_scene *sc = w->sc;
    if (pd_csv_open(&w->csv, w->out.tmp))
        return w->csv.failure;
    pd_provenance_csv(&w->csv, &w->prov);
    pd_csv_printf(&w->csv, "# units = s");
    for (int part = 0; part < 2; part++)
        for (int k = 0; k < sc->n; k++)
            pd_csv_printf(&w->csv, ",%s", part ? "m/s" : "m");
    for (int part = 0; part < 2; part++)
        for (int a = 0; a < sc->ncontact; a++)
            pd_csv_printf(&w->csv, ",%s", part ? "N s" : "m");
    for (int k = 0; k < w->nup; k++)
        pd_csv_printf(&w->csv, ",m");
    for (int k = 0; k < sc->n; k++)
        pd_csv_printf(&w->csv, ",m/s^2");
    for (int a = 0; w->forces && a < sc->ncontact; a++)
        pd_csv_printf(&w->csv, ",N");
    pd_csv_printf(&w->csv, "\nt");
    for (int s = 0; s < sc->nstruct; s++)
        for (int k = 1; k <= sc->st[s].storeys; k++)
            pd_csv_printf(&w->csv, ",%s.x%d", sc->st[s].name, k);
    for (int s = 0; s < sc->nstruct; s++)
        for (int k = 1; k <= sc->st[s].storeys; k++)
            pd_csv_printf(&w->csv, ",%s.v%d", sc->st[s].name, k);
    for (int a = 0; a < sc->ncontact; a++) /* the rows hold every gap, then every impulse */
        pd_csv_printf(&w->csv, ",c%d.gap", a);
    for (int a = 0; a < sc->ncontact; a++)
        pd_csv_printf(&w->csv, ",c%d.impulse", a);
    for (int s = 0; s < sc->nstruct; s++) /* the yielding structures' offsets */
        for (int k = 1; yields(sc, s) && k <= sc->st[s].storeys; k++)
            pd_csv_printf(&w->csv, ",%s.up%d", sc->st[s].name, k);
    for (int s = 0; s < sc->nstruct; s++) /* the floors' absolute accelerations */
        for (int k = 1; k <= sc->st[s].storeys; k++)
            pd_csv_printf(&w->csv, ",%s.a%d", sc->st[s].name, k);
    for (int a = 0; w->forces && a < sc->ncontact; a++)
        pd_csv_printf(&w->csv, ",c%d.force", a);
    pd_csv_printf(&w->csv, "\n");
    return w->csv.failure;
}

/* Close every dataset id (those not open are -1): 0, or -1 when one failed. */
static int close_datasets(pd_scene_writer *w)
{
    hid_t *sets[] = {w->ds_x, w->ds_v, w->ds_up, w->ds_a, w->ds_g, w->ds_p, w->ds_f};
    int counts[] = {w->sc->nstruct,  w->sc->nstruct,  w->sc->nstruct, w->sc->nstruct,
                    w->sc->ncontact, w->sc->ncontact, w->sc->ncontact},
        rc = 0;
    for (int k = 0; k < 7; k++)
        for (int i = 0; sets[k] && i < counts[k]; i++)
            rc |= pd_h5_close_id(&sets[k][i]);
    rc |= pd_h5_close_id(&w->ds_t);
    return rc ? -1 : 0;
}

void pd_scene_writer_free(pd_scene_writer *w)
{
    if (!w)
        return;
    if (w->csv.f)
        pd_csv_close(&w->csv);
    close_datasets(w);
    pd_h5_close(&w->file, &w->failure);
    pd_outfile_abort(&w->out);
    free(w->imp);
    free(w->buf);
    free(w->col);
    free(w->ds_x);
    free(w->ds_v);
    free(w->ds_up);
    free(w->ds_a);
    free(w->ds_g);
    free(w->ds_p);
    free(w->ds_f);
    free(w);
}

/* Every dataset id not open (-1); 0, or -1 without the arrays. */
static int ids_init(pd_scene_writer *w, int m)
{
    const pd_scene *sc = w->sc;
    w->ds_x = malloc((size_t)sc->nstruct * sizeof(hid_t));
    w->ds_v = malloc((size_t)sc->nstruct * sizeof(hid_t));
    w->ds_up = malloc((size_t)sc->nstruct * sizeof(hid_t));
    w->ds_a = malloc((size_t)sc->nstruct * sizeof(hid_t));
    w->ds_g = malloc((size_t)m * sizeof(hid_t));
    w->ds_p = malloc((size_t)m * sizeof(hid_t));
    w->ds_f = malloc((size_t)m * sizeof(hid_t));
    int ok = w->ds_x && w->ds_v && w->ds_up && w->ds_a && w->ds_g && w->ds_p && w->ds_f;
    for (int s = 0; ok && s < sc->nstruct; s++)
        w->ds_x[s] = w->ds_v[s] = w->ds_up[s] = w->ds_a[s] = -1;
    for (int a = 0; ok && a < m; a++)
        w->ds_g[a] = w->ds_p[a] = w->ds_f[a] = -1;
    return ok ? 0 : -1;
}

/* The HDF5 layout keeps two datasets open per structure and per contact,
 * about 70 kB of the library's memory each group (10,000 structures: 690 MB
 * and 6.5 s to write); more groups than this are refused up front. */
#define SCENE_H5_GROUPS_MAX 5000

int pd_scene_writer_open(pd_scene_writer **out, const char *path, const pd_scene *sc, long every,
                         int forces, pd_err *err)
{
    pd_scene_writer *w;
    int smax = 1, m = sc->ncontact > 0 ? sc->ncontact : 1, rc, e;
    int hdf5 = ends_with(path, ".h5") || ends_with(path, ".hdf5");
    *out = NULL;
    if (hdf5 && sc->nstruct + sc->ncontact > SCENE_H5_GROUPS_MAX)
        return pd_err_set(err, PD_EINVAL,
                          "-o %s: %d structures and %d contacts are more than an HDF5 file holds "
                          "here (at most %d groups in all); write CSV (-o FILE.csv)",
                          path, sc->nstruct, sc->ncontact, SCENE_H5_GROUPS_MAX);
    if (!(w = calloc(1, sizeof *w)))
        return pd_err_set(err, PD_ENOMEM, "-o %s: out of memory", path);
    w->sc = sc;
    w->every = every;
    w->file = w->ds_t = -1;
    w->out.slot = -1;
    w->hdf5 = hdf5;
    w->forces = forces && sc->ncontact > 0;
    pd_provenance_now(&w->prov, PD_FORMAT_SCENE);
    for (int s = 0; s < sc->nstruct; s++)
        w->nup += yields(sc, s) ? sc->st[s].storeys : 0;
    w->width = 1 + 3 * sc->n + 2 * sc->ncontact + w->nup + (w->forces ? sc->ncontact : 0);
    w->cap = OUT_BUFFER_DOUBLES / w->width;
    w->cap = w->cap < 16 ? 16 : w->cap > 4096 ? 4096 : w->cap;
    for (int s = 0; s < sc->nstruct; s++)
        smax = sc->st[s].storeys > smax ? sc->st[s].storeys : smax;
    w->imp = calloc((size_t)m, sizeof(double));
    w->buf = malloc((size_t)w->cap * (size_t)w->width * sizeof(double));
    w->col = malloc((size_t)w->cap * (size_t)smax * sizeof(double));
    if (ids_init(w, m) || !w->imp || !w->buf || !w->col)
        rc = pd_err_set(err, PD_ENOMEM, "-o %s: out of memory for the row buffer", path);
    else if (!(rc = pd_outfile_begin(&w->out, "-o", path, err)) &&
             (e = w->hdf5 ? h5_open(w) : csv_open(w)))
        rc = pd_outfile_error(&w->out, e, err);
    if (rc) {
        pd_scene_writer_free(w);
        return rc;
    }
    *out = w;
    return PD_OK;
}

/* Write the buffered rows. */
static int flush_rows(pd_scene_writer *w)
{
    const pd_scene *sc = w->sc;
    long nb = w->nbuf;
    int n = sc->n, m = sc->ncontact, rc = 0;
    if (nb == 0 || w->failure)
        return w->failure ? -1 : 0;
    if (w->hdf5 && (w->failure = pd_h5_headroom(PD_H5_HEADROOM + 8.0 * (double)nb * w->width)))
        return -1;
    if (!w->hdf5) {
        for (long r = 0; r < nb; r++) {
            const double *row = w->buf + (size_t)r * w->width;
            for (int k = 0; k < w->width; k++)
                pd_csv_printf(&w->csv, "%.17g%c", row[k], k + 1 < w->width ? ',' : '\n');
        }
        w->failure = w->csv.failure;
    } else {
        for (long r = 0; r < nb; r++)
            w->col[r] = w->buf[(size_t)r * w->width];
        rc = pd_h5_append(w->ds_t, H5T_NATIVE_DOUBLE, w->rows - nb, nb, 0, w->col);
        for (int s = 0; s < sc->nstruct && !rc; s++)
            for (int part = 0; part < 2 && !rc; part++) {
                int st = sc->st[s].storeys, off = 1 + part * n + sc->st[s].dof;
                for (long r = 0; r < nb; r++)
                    memcpy(w->col + (size_t)r * st, w->buf + (size_t)r * w->width + off,
                           (size_t)st * sizeof(double));
                rc = pd_h5_append(part ? w->ds_v[s] : w->ds_x[s], H5T_NATIVE_DOUBLE, w->rows - nb,
                                  nb, st, w->col);
            }
        for (int a = 0; a < m && !rc; a++)
            for (int part = 0; part < 2 && !rc; part++) {
                for (long r = 0; r < nb; r++)
                    w->col[r] = w->buf[(size_t)r * w->width + 1 + 2 * n + part * m + a];
                rc = pd_h5_append(part ? w->ds_p[a] : w->ds_g[a], H5T_NATIVE_DOUBLE, w->rows - nb,
                                  nb, 0, w->col);
            }
        for (int s = 0, off = 1 + 2 * n + 2 * m; s < sc->nstruct && !rc; s++) {
            if (!yields(sc, s))
                continue;
            int st = sc->st[s].storeys; /* the yielding structures' offsets, in file order */
            for (long r = 0; r < nb; r++)
                memcpy(w->col + (size_t)r * st, w->buf + (size_t)r * w->width + off,
                       (size_t)st * sizeof(double));
            rc = pd_h5_append(w->ds_up[s], H5T_NATIVE_DOUBLE, w->rows - nb, nb, st, w->col);
            off += st;
        }
        for (int s = 0; s < sc->nstruct && !rc; s++) { /* the floors' accelerations */
            int st = sc->st[s].storeys, off = 1 + 2 * n + 2 * m + w->nup + sc->st[s].dof;
            for (long r = 0; r < nb; r++)
                memcpy(w->col + (size_t)r * st, w->buf + (size_t)r * w->width + off,
                       (size_t)st * sizeof(double));
            rc = pd_h5_append(w->ds_a[s], H5T_NATIVE_DOUBLE, w->rows - nb, nb, st, w->col);
        }
        for (int a = 0; w->forces && a < m && !rc; a++) {
            for (long r = 0; r < nb; r++)
                w->col[r] = w->buf[(size_t)r * w->width + 1 + 3 * n + 2 * m + w->nup + a];
            rc = pd_h5_append(w->ds_f[a], H5T_NATIVE_DOUBLE, w->rows - nb, nb, 0, w->col);
        }
    }
    w->nbuf = 0;
    if (rc && !w->failure)
        w->failure = w->hdf5 ? pd_h5_errno() : EIO;
    return w->failure ? -1 : 0;
}

int pd_scene_writer_sample(const pd_scene_sample *s, void *ctx)
{
    pd_scene_writer *w = ctx;
    const pd_scene *sc = w->sc;
    int n = sc->n, m = sc->ncontact;
    for (int a = 0; a < m && s->impulse; a++)
        w->imp[a] += s->impulse[a];
    if (w->seen++ % w->every)
        return 0;
    double *row = w->buf + (size_t)w->nbuf * w->width;
    row[0] = s->t;
    memcpy(row + 1, s->x, (size_t)n * sizeof(double));
    memcpy(row + 1 + n, s->v, (size_t)n * sizeof(double));
    for (int a = 0; a < m; a++) {
        row[1 + 2 * n + a] = s->gap ? s->gap[a] : 0.0;
        row[1 + 2 * n + m + a] = w->imp[a];
        w->imp[a] = 0.0;
    }
    double *up = row + 1 + 2 * n + 2 * m;
    for (int st = 0; st < sc->nstruct; st++) /* the yielding structures' storeys */
        for (int k = 0; yields(sc, st) && k < sc->st[st].storeys; k++)
            *up++ = s->up ? s->up[sc->st[st].dof + k] : 0.0;
    for (int i = 0; i < n; i++) /* the floors' absolute accelerations (NAN: not measured) */
        *up++ = s->a_abs ? s->a_abs[i] : NAN;
    for (int a = 0; w->forces && a < m; a++) /* the elements' forces */
        *up++ = s->force ? s->force[a] : 0.0;
    w->nbuf++;
    w->rows++;
    if (w->nbuf == w->cap && flush_rows(w))
        return 1; /* stop the run: the file cannot be written */
    return 0;
}

/* ---- the results at the end ----------------------------------------------- */

/* One attribute line of the CSV, or one attribute of obj. */
static int put_num(pd_scene_writer *w, hid_t obj, const char *prefix, const char *name, double x,
                   const char *units)
{
    if (w->hdf5)
        return pd_h5_num(obj, name, x, units);
    return pd_csv_printf(&w->csv, "# %s%s = %.17g%s%s%s\n", prefix, name, x, units ? " [" : "",
                         units ? units : "", units ? "]" : "");
}

static int put_text(pd_scene_writer *w, hid_t obj, const char *prefix, const char *name,
                    const char *text)
{
    if (w->hdf5)
        return pd_h5_attr(obj, name, text, 0.0);
    char full[PD_NAME_MAX + 48];
    snprintf(full, sizeof full, "%s%s", prefix, name);
    return pd_csv_comment(&w->csv, full, text);
}

static int put_nums(pd_scene_writer *w, hid_t obj, const char *prefix, const char *name, int n,
                    const double *x, const char *units)
{
    if (w->hdf5)
        return pd_h5_nums(obj, name, n, x, units);
    pd_csv_printf(&w->csv, "# %s%s = [", prefix, name);
    for (int i = 0; i < n; i++)
        pd_csv_printf(&w->csv, "%s%.17g", i ? ", " : "", x[i]);
    return pd_csv_printf(&w->csv, "]%s%s%s\n", units ? " [" : "", units ? units : "",
                         units ? "]" : "");
}

/* A yielding scene's energy balance (NaN: not by Moreau-Jean). */
static int put_energy(pd_scene_writer *w, hid_t f, const pd_scene *sc, const pd_scene_result *r)
{
    if (pd_scene_springs(sc) == 0)
        return 0;
    const pd_energy *en = &r->energy;
    return put_num(w, f, "", "energy_input", en->input, "J") ||
           put_num(w, f, "", "energy_kinetic", en->kinetic, "J") ||
           put_num(w, f, "", "energy_strain", en->strain, "J") ||
           put_num(w, f, "", "energy_damping", en->damping, "J") ||
           put_num(w, f, "", "energy_hysteretic", en->hysteretic, "J") ||
           put_num(w, f, "", "energy_impact", en->impact, "J") ||
           put_num(w, f, "", "energy_residual", en->residual, "1");
}

/* The run's inputs and figures on the root. */
static int put_run(pd_scene_writer *w, const pd_scene_run_info *ri)
{
    const pd_scene *sc = w->sc;
    const pd_scene_result *r = &ri->sum->r;
    hid_t f = w->hdf5 ? w->file : -1;
    return put_text(w, f, "", "scene", ri->scene_name) || put_text(w, f, "", "method", r->method) ||
           put_text(w, f, "", "kernel", r->kernel) || put_text(w, f, "", "factor", r->factor) ||
           put_text(w, f, "", "lcp_solver", r->lcp_solver) ||
           put_text(w, f, "", "pulse",
                    sc->exc.record ? sc->exc.record->name : pd_pulse_name(sc->exc.pulse)) ||
           put_num(w, f, "", "scale", sc->exc.record ? sc->exc.scale : 1.0, "1") ||
           put_text(w, f, "", "dir", sc->exc.dir > 0 ? "+x" : "-x") ||
           put_num(w, f, "", "ap", sc->exc.ap, "m/s^2") ||
           put_num(w, f, "", "Tp", sc->exc.Tp, "s") ||
           put_num(w, f, "", "Le", pd_scene_Le(sc), "m") || put_num(w, f, "", "dt", r->dt, "s") ||
           put_num(w, f, "", "theta", r->theta, "1") || put_num(w, f, "", "tend", r->tend, "s") ||
           put_num(w, f, "", "every", (double)w->every, "1") ||
           put_num(w, f, "", "steps", (double)r->steps, "1") ||
           put_num(w, f, "", "simultaneous", (double)r->simultaneous, "1") ||
           put_num(w, f, "", "tol_closed", (double)r->tol_closed, "1") ||
           put_num(w, f, "", "accumulations", (double)r->accumulations, "1") ||
           put_num(w, f, "", "close_tol", r->close_tol, "Le") ||
           put_text(w, f, "", "impact_law", r->impact_law ? r->impact_law : "none") ||
           put_num(w, f, "", "law_band", r->law_band_max, "1") ||
           put_num(w, f, "", "contact_duration", r->contact_duration, "s") ||
           put_num(w, f, "", "cpu_s", ri->sum->cpu_s, "s") ||
           put_num(w, f, "", "rtol", r->rtol, "1") ||
           put_num(w, f, "", "err_est", ri->sum->err_est, "1") ||
           put_num(w, f, "", "rtol_met", ri->sum->rtol_met, "1") ||
           put_num(w, f, "", "steps_rejected", (double)r->steps_rejected, "1") ||
           put_num(w, f, "", "dt_min", r->dt_min, "s") ||
           put_num(w, f, "", "dt_max", r->dt_max, "s") || put_energy(w, f, sc, r);
}

/* Structure s: its description and results (group /structures/NAME). */
static int put_structure(pd_scene_writer *w, const pd_scene_summary *sum, int s)
{
    const pd_structure *st = &w->sc->st[s];
    char prefix[PD_NAME_MAX + 2];
    hid_t g = -1;
    int rc, o = st->dof, k = st->storeys;
    snprintf(prefix, sizeof prefix, "%s.", st->name);
    if (w->hdf5) {
        char path[PD_NAME_MAX + 16];
        snprintf(path, sizeof path, "structures/%s", st->name);
        if ((g = H5Gopen2(w->file, path, H5P_DEFAULT)) < 0)
            return -1;
    }
    rc = put_num(w, g, prefix, "storeys", k, "1") || put_num(w, g, prefix, "T0", st->T0, "s") ||
         put_num(w, g, prefix, "Pi2", sum->Pi2[s], "1") ||
         put_num(w, g, prefix, "xi", st->xi, "1") ||
         put_text(w, g, prefix, "damping",
                  st->storeys == 1                      ? "exact"
                  : st->damping == PD_DAMPING_STIFFNESS ? "stiffness"
                                                        : "rayleigh") ||
         put_num(w, g, prefix, "alpha", st->alpha, "1/s") ||
         put_num(w, g, prefix, "beta", st->beta, "s") ||
         put_nums(w, g, prefix, "masses", k, st->mass, "kg") ||
         put_nums(w, g, prefix, "stiffnesses", k, st->stiffness, "N/m") ||
         put_nums(w, g, prefix, "umax", k, sum->r.umax + o, "m") ||
         put_nums(w, g, prefix, "u_pos", k, sum->r.u_pos + o, "m") ||
         put_nums(w, g, prefix, "u_neg", k, sum->r.u_neg + o, "m") ||
         put_nums(w, g, prefix, "drift", k, sum->r.drift + o, "m") ||
         put_nums(w, g, prefix, "storey_heights", k, st->height, "m") ||
         put_nums(w, g, prefix, "drift_ratio", k, sum->r.drift_ratio + o, "1") ||
         put_nums(w, g, prefix, "acc_max", k, sum->r.acc_max + o, "m/s^2") ||
         put_nums(w, g, prefix, "shear_max", k, sum->r.shear_max + o, "N") ||
         put_num(w, g, prefix, "base_shear_max", sum->r.shear_max[o], "N") ||
         put_nums(w, g, prefix, "Pi1", k, sum->Pi1 + o, "1") ||
         put_nums(w, g, prefix, "umax_free", k, sum->free.umax + o, "m") ||
         put_nums(w, g, prefix, "gamma", k, sum->gamma + o, "1") ||
         put_num(w, g, prefix, "err_est", sum->err_est_structure[s], "1") ||
         put_num(w, g, prefix, "law_band", sum->r.law_band[s], "1");
    if (!rc && st->uy) { /* yielding storeys (SPEC §7); the onsets as numbers */
        double *ny = malloc((size_t)k * sizeof(double));
        for (int i = 0; ny && i < k; i++)
            ny[i] = (double)sum->r.n_yield[o + i];
        rc = !ny || put_nums(w, g, prefix, "uy", k, st->uy, "m") ||
             put_nums(w, g, prefix, "yield_alpha", k, st->yield_alpha, "1") ||
             put_nums(w, g, prefix, "ductility", k, sum->r.ductility + o, "1") ||
             put_nums(w, g, prefix, "residual", k, sum->r.residual + o, "m") ||
             put_nums(w, g, prefix, "plastic_excursion", k, sum->r.plastic_excursion + o, "m") ||
             put_nums(w, g, prefix, "n_yield", k, ny, "1");
        free(ny);
    }
    if (g >= 0 && H5Gclose(g) < 0)
        rc = -1;
    return rc;
}

/* Contact a: its description and results (group /contacts/A). */
static int put_contact(pd_scene_writer *w, const pd_scene_summary *sum, int a)
{
    const pd_scene *sc = w->sc;
    const pd_contact *ct = &sc->ct[a];
    char prefix[32];
    hid_t g = -1;
    int rc;
    snprintf(prefix, sizeof prefix, "c%d.", a);
    if (w->hdf5) {
        char path[48];
        snprintf(path, sizeof path, "contacts/%d", a);
        if ((g = H5Gopen2(w->file, path, H5P_DEFAULT)) < 0)
            return -1;
    }
    /* its name, as Python's coordinates give it: the sides and the level */
    char name[2 * PD_NAME_MAX + 32];
    snprintf(name, sizeof name, "%s-%s@%d", ct->a == PD_WALL ? "wall" : sc->st[ct->a].name,
             ct->b == PD_WALL ? "wall" : sc->st[ct->b].name,
             ct->a == PD_WALL ? ct->level_b : ct->level_a);
    rc = put_text(w, g, prefix, "name", name) ||
         put_text(w, g, prefix, "a", ct->a == PD_WALL ? "wall" : sc->st[ct->a].name) ||
         put_text(w, g, prefix, "b", ct->b == PD_WALL ? "wall" : sc->st[ct->b].name) ||
         put_num(w, g, prefix, "level_a", ct->level_a, "1") ||
         put_num(w, g, prefix, "level_b", ct->level_b, "1") ||
         put_num(w, g, prefix, "gap0", ct->gap, "m") ||
         put_num(w, g, prefix, "eps", ct->eps, "1") ||
         put_num(w, g, prefix, "Pi3", sum->Pi3[a], "1") ||
         put_num(w, g, prefix, "chi", sum->chi[a], "1") ||
         put_num(w, g, prefix, "required_gap", sum->required_gap[a], "m") ||
         put_num(w, g, prefix, "gap_abs", sum->rule_abs[a], "m") ||
         put_num(w, g, prefix, "gap_srss", sum->rule_srss[a], "m") ||
         put_num(w, g, prefix, "gap_ddc", sum->rule_ddc[a], "m") ||
         put_num(w, g, prefix, "impacts", (double)sum->r.impacts[a], "1") ||
         put_num(w, g, prefix, "first_impact", sum->r.first_impact[a], "s") ||
         put_num(w, g, prefix, "max_impulse", sum->r.max_impulse[a], "N s") ||
         put_num(w, g, prefix, "contact_time", sum->r.contact_time[a], "s") ||
         put_num(w, g, prefix, "approach", sum->r.approach[a], "m") ||
         put_num(w, g, prefix, "force_equiv", sum->r.force_equiv[a], "N") ||
         put_num(w, g, prefix, "force_max", sum->r.force_max[a], "N");
    if (g >= 0 && H5Gclose(g) < 0)
        rc = -1;
    return rc;
}

int pd_scene_writer_finish(pd_scene_writer *w, const pd_scene_run_info *ri, pd_err *err)
{
    int rc = flush_rows(w) || put_run(w, ri), e;
    for (int s = 0; s < w->sc->nstruct && !rc; s++)
        rc = put_structure(w, ri->sum, s);
    for (int a = 0; a < w->sc->ncontact && !rc; a++)
        rc = put_contact(w, ri->sum, a);
    if (w->hdf5) {
        rc |= close_datasets(w);
        e = pd_h5_close(&w->file, &w->failure);
    } else
        e = pd_csv_close(&w->csv);
    if (e || rc) {
        pd_outfile_abort(&w->out);
        return pd_outfile_error(&w->out, e ? e : w->failure, err);
    }
    return pd_outfile_commit(&w->out, err);
}
