/* spectrum_scene.c — `pound spectrum --scene`: Pi1(Pi2) of every structure of
 * a scene at each listed Pi3 and eps (pd_problems.h, "scene sweeps"), as a
 * table (HDF5 or CSV, one row per point), a chart, JSON or text. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "pd_output.h"
#include "pd_plot.h"
#include "pd_spectrum.h"

#define SCENE_CURVES 12 /* most curves on the chart */

/* What the sweep computed, and the rows derived from it. */
typedef struct sweep_out {
    const pd_scene *sc;
    pd_scene_sweep w;
    long ntw, np;
    pd_scene_point *pts; /* twins then points */
    double *umax;        /* task x nstruct */
    double *Pi1, *gamma; /* point x nstruct */
} sweep_out;

/* Rows: Pi1 = umax / Le and gamma = umax / umax of the twin (same Pi2). */
static void derive(sweep_out *o)
{
    int ns = o->sc->nstruct;
    for (long p = 0; p < o->np; p++) {
        long t = o->ntw + p, twin = p % o->w.npi2;
        for (int s = 0; s < ns; s++) {
            double u = o->umax[(size_t)t * ns + s], uf = o->umax[(size_t)twin * ns + s];
            o->Pi1[(size_t)p * ns + s] = u / o->pts[t].Le;
            o->gamma[(size_t)p * ns + s] = uf > 0.0 ? u / uf : NAN;
        }
    }
}

/* The exact reference's closing tolerance [Le]; NaN for the other methods. */
static double close_tol(const sweep_out *o)
{
    return o->w.opts.method == PD_METHOD_EVENT ? o->w.opts.close_tol : NAN;
}

/* The table: Pi2, Pi3, eps, Tp, impacts, then Pi1, gamma, umax per structure. */
static int write_table(const pd_scene_sweep_args *a, const sweep_out *o, pd_err *err)
{
    int ns = o->sc->nstruct, ncols = 6 + 3 * ns, rc;
    long np = o->np;
    double *data = malloc((size_t)ncols * (size_t)np * sizeof(double));
    pd_column *cols = malloc((size_t)ncols * sizeof *cols);
    char *names = malloc((size_t)ns * 3 * (PD_NAME_MAX + 8));
    if (!data || !cols || !names) {
        free(data);
        free(cols);
        free(names);
        return pd_err_set(err, PD_ENOMEM, "out of memory for the table");
    }
    static const char *const head[] = {"Pi2", "Pi3", "eps", "Tp", "impacts", "steps"};
    static const char *const units[] = {"1", "1", "1", "s", "1", "1"};
    for (int c = 0; c < 6; c++)
        cols[c] = (pd_column){.name = head[c], .units = units[c], .values = data + (size_t)c * np};
    for (int s = 0; s < ns; s++)
        for (int q = 0; q < 3; q++) {
            char *nm = names + (size_t)(3 * s + q) * (PD_NAME_MAX + 8);
            snprintf(nm, PD_NAME_MAX + 8, "%s.%s", o->sc->st[s].name,
                     q == 0   ? "Pi1"
                     : q == 1 ? "gamma"
                              : "umax");
            cols[6 + 3 * s + q] = (pd_column){.name = nm,
                                              .units = q == 2 ? "m" : "1",
                                              .values = data + (size_t)(6 + 3 * s + q) * np};
        }
    for (long p = 0; p < np; p++) {
        const pd_scene_point *pt = &o->pts[o->ntw + p];
        double v[6] = {pt->Pi2, pt->Pi3, pt->eps, pt->Tp, (double)pt->impacts, (double)pt->steps};
        for (int c = 0; c < 6; c++)
            data[(size_t)c * np + p] = v[c];
        for (int s = 0; s < ns; s++) {
            data[(size_t)(6 + 3 * s) * np + p] = o->Pi1[(size_t)p * ns + s];
            data[(size_t)(7 + 3 * s) * np + p] = o->gamma[(size_t)p * ns + s];
            data[(size_t)(8 + 3 * s) * np + p] = o->umax[(size_t)(o->ntw + p) * ns + s];
        }
    }
    pd_attr attrs[] = {{.name = "scene", .is_text = 1, .text = a->k->scene_path},
                       {.name = "reference", .is_text = 1, .text = o->sc->st[o->w.ref].name},
                       {.name = "reference_T0", .units = "s", .num = o->sc->st[o->w.ref].T0},
                       {.name = "reference_contact", .units = "1", .num = o->w.ref_contact},
                       {.name = "method", .is_text = 1, .text = pd_method_name(o->w.opts.method)},
                       {.name = "close_tol", .units = "Le", .num = close_tol(o)},
                       {.name = "ap", .units = "m/s^2", .num = o->sc->exc.ap}};
    pd_table t = {.rows = np,
                  .ncols = ncols,
                  .cols = cols,
                  .nattrs = (int)(sizeof attrs / sizeof attrs[0]),
                  .attrs = attrs,
                  .dim = "point"};
    rc = pd_output_write(a->out, &t, err);
    free(data);
    free(cols);
    free(names);
    return rc;
}

/* Pi1 against Pi2: one curve per structure and (Pi3, eps), at most SCENE_CURVES. */
static int draw(const pd_scene_sweep_args *a, const sweep_out *o, pd_err *err)
{
    int ns = o->sc->nstruct, nc = 0, npi2 = o->w.npi2;
    long ncurves = o->np / npi2;
    pd_curve cv[SCENE_CURVES];
    char labels[SCENE_CURVES][PD_NAME_MAX + 48];
    double *x = malloc((size_t)SCENE_CURVES * npi2 * sizeof(double));
    double *y = malloc((size_t)SCENE_CURVES * npi2 * sizeof(double));
    if (!x || !y) {
        free(x);
        free(y);
        return pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
    }
    for (long c = 0; c < ncurves && nc < SCENE_CURVES; c++)
        for (int s = 0; s < ns && nc < SCENE_CURVES; s++, nc++) {
            const pd_scene_point *pt = &o->pts[o->ntw + c * npi2];
            for (int j = 0; j < npi2; j++) {
                x[(size_t)nc * npi2 + j] = o->pts[o->ntw + c * npi2 + j].Pi2;
                y[(size_t)nc * npi2 + j] = o->Pi1[(size_t)(c * npi2 + j) * ns + s];
            }
            snprintf(labels[nc], sizeof labels[nc], "%s, \u03a0\u2083 = %.3g, \u03b5 = %.3g",
                     o->sc->st[s].name, pt->Pi3, pt->eps);
            cv[nc] = (pd_curve){.label = labels[nc],
                                .n = npi2,
                                .x = x + (size_t)nc * npi2,
                                .y = y + (size_t)nc * npi2};
        }
    char title[256];
    snprintf(title, sizeof title, "%s: \u03a0\u2082 of %s", a->k->scene_path,
             o->sc->st[o->w.ref].name);
    pd_chart ch = {.title = title,
                   .xlabel = "{/Symbol P}_2 = T_p / T_0",
                   .ylabel = "{/Symbol P}_1 = u_{max} {/Symbol w}_p^2 / a_p",
                   .logx = 1,
                   .logy = 1,
                   .ncurves = nc,
                   .curves = cv,
                   .vline = NAN};
    int rc = pd_plot(a->plot, &ch, err);
    free(x);
    free(y);
    return rc;
}

static void print_json(const sweep_out *o, double cpu, double wall)
{
    pd_json js;
    int ns = o->sc->nstruct;
    pd_json_init(&js, stdout);
    pd_json_begin_object(&js, NULL);
    pd_json_str(&js, "reference", o->sc->st[o->w.ref].name);
    pd_json_str(&js, "method", pd_method_name(o->w.opts.method));
    pd_json_num(&js, "close_tol", close_tol(o));
    pd_json_begin_array(&js, "points");
    for (long p = 0; p < o->np; p++) {
        const pd_scene_point *pt = &o->pts[o->ntw + p];
        pd_json_begin_object(&js, NULL);
        pd_json_num(&js, "Pi2", pt->Pi2);
        pd_json_num(&js, "Pi3", pt->Pi3);
        pd_json_num(&js, "eps", pt->eps);
        pd_json_num(&js, "Tp", pt->Tp);
        pd_json_int(&js, "impacts", pt->impacts);
        pd_json_begin_array(&js, "structures");
        for (int s = 0; s < ns; s++) {
            pd_json_begin_object(&js, NULL);
            pd_json_str(&js, "name", o->sc->st[s].name);
            pd_json_num(&js, "Pi1", o->Pi1[(size_t)p * ns + s]);
            pd_json_num(&js, "gamma", o->gamma[(size_t)p * ns + s]);
            pd_json_num(&js, "umax", o->umax[(size_t)(o->ntw + p) * ns + s]);
            pd_json_end_object(&js);
        }
        pd_json_end_array(&js);
        pd_json_end_object(&js);
    }
    pd_json_end_array(&js);
    pd_json_num(&js, "cpu_s", cpu);
    pd_json_num(&js, "wall_s", wall);
    pd_json_end_object(&js);
    pd_json_finish(&js);
}

static void print_text(const pd_scene_sweep_args *a, const sweep_out *o, double cpu, double wall)
{
    int ns = o->sc->nstruct, show = ns < 6 ? ns : 6;
    printf("scene %s: Pi2 of %s (T0 = %.4g s), %ld points, %s; cpu %.3g s, wall %.3g s\n",
           a->k->scene_path, o->sc->st[o->w.ref].name, o->sc->st[o->w.ref].T0, o->np,
           pd_method_name(o->w.opts.method), cpu, wall);
    printf("  %10s %10s %6s %8s", "Pi2", "Pi3", "eps", "impacts");
    for (int s = 0; s < show; s++)
        printf(" %14.14s", o->sc->st[s].name);
    printf("   (Pi1 per structure)\n");
    for (long p = 0; p < o->np; p++) {
        const pd_scene_point *pt = &o->pts[o->ntw + p];
        printf("  %10.4g %10.4g %6.3g %8ld", pt->Pi2, pt->Pi3, pt->eps, pt->impacts);
        for (int s = 0; s < show; s++)
            printf(" %14.6g", o->Pi1[(size_t)p * ns + s]);
        putchar('\n');
    }
}

int pd_cmd_spectrum_scene(const pd_scene_sweep_args *a, double wall0)
{
    pd_scene *sc = NULL;
    sweep_out o;
    pd_err err;
    int status, rc;
    memset(&o, 0, sizeof o);
    if ((status = pd_cli_scene(a->k, &sc)))
        return status;
    o.sc = sc;
    o.w = (pd_scene_sweep){.sc = sc,
                           .opts = a->k->opts,
                           .ref = a->ref_name ? pd_scene_find(sc, a->ref_name) : 0,
                           .ref_contact = a->ref_contact,
                           .pi2_min = a->pi2_min,
                           .pi2_max = a->pi2_max,
                           .npi2 = a->npi2,
                           .linear = a->linear,
                           .npi3 = a->npi3,
                           .neps = a->neps,
                           .pi3 = a->pi3,
                           .eps = a->eps};
    if (a->ref_name && o.w.ref < 0) {
        status = pd_cli_usage_error("--ref: '%s' is not a structure of %s", a->ref_name,
                                    a->k->scene_path);
        goto done;
    }
    if (pd_scene_sweep_check(&o.w, &err)) {
        status = pd_cli_usage_error("--%s", err.msg);
        goto done;
    }
    o.ntw = pd_scene_sweep_twins(&o.w);
    o.np = pd_scene_sweep_points(&o.w);
    int ns = sc->nstruct;
    o.pts = calloc((size_t)(o.ntw + o.np), sizeof *o.pts);
    o.umax = calloc((size_t)(o.ntw + o.np) * ns, sizeof(double));
    o.Pi1 = calloc((size_t)o.np * ns, sizeof(double));
    o.gamma = calloc((size_t)o.np * ns, sizeof(double));
    if (!o.pts || !o.umax || !o.Pi1 || !o.gamma) {
        fprintf(stderr, "pound: spectrum: out of memory for %ld points\n", o.np);
        status = 1;
        goto done;
    }
    if ((rc = pd_scene_sweep_run(&o.w, a->threads, o.pts, o.umax, &err))) {
        fprintf(stderr, "pound: spectrum: %s\n", err.msg);
        status = rc == PD_EINVAL ? 2 : 1;
        goto done;
    }
    derive(&o);
    double cpu = 0.0;
    for (long t = 0; t < o.ntw + o.np; t++)
        cpu += o.pts[t].cpu_s;
    if ((a->out && write_table(a, &o, &err)) || (a->plot && draw(a, &o, &err))) {
        fprintf(stderr, "pound: spectrum: %s\n", err.msg);
        status = 1;
        goto done;
    }
    if (a->json)
        print_json(&o, cpu, pd_wall_seconds() - wall0);
    else
        print_text(a, &o, cpu, pd_wall_seconds() - wall0);
done:
    free(o.pts);
    free(o.umax);
    free(o.Pi1);
    free(o.gamma);
    pd_scene_free(sc);
    return status;
}
