/* scene_plot.c — (cli) the displacement histories of a scene run, one
 * curve per structure (its top storey), with every impact marked on the
 * structure it hits, drawn by gnuplot. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_plot.h"
#include "pd_scene_out.h"

#define PLOT_CURVES 12     /* most structures drawn */
#define PLOT_POINTS 2000   /* points per curve (the samples are decimated) */
#define PLOT_MARKS 4000    /* most impacts marked */

struct pd_scene_plot {
    const pd_scene *sc;
    int ncurves, *which;  /* structures drawn */
    long stride, seen, np;
    double *t, *y;        /* np times; ncurves x PLOT_POINTS displacements */
    long nmarks;
    double *mt, *my;      /* impacts: time and displacement of the structure hit */
    double *imp;          /* m: impulses since the last kept sample */
};

void pd_scene_plot_free(pd_scene_plot *p)
{
    if (!p)
        return;
    free(p->which);
    free(p->t);
    free(p->y);
    free(p->mt);
    free(p->my);
    free(p->imp);
    free(p);
}

int pd_scene_plot_open(pd_scene_plot **out, const pd_scene *sc, long expected, pd_err *err)
{
    pd_scene_plot *p = calloc(1, sizeof *p);
    *out = NULL;
    if (!p)
        return pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
    p->sc = sc;
    p->ncurves = sc->nstruct < PLOT_CURVES ? sc->nstruct : PLOT_CURVES;
    p->stride = expected / PLOT_POINTS + 1;
    p->which = malloc((size_t)p->ncurves * sizeof(int));
    p->t = malloc((PLOT_POINTS + 2) * sizeof(double));
    p->y = malloc((size_t)p->ncurves * (PLOT_POINTS + 2) * sizeof(double));
    p->mt = malloc(PLOT_MARKS * sizeof(double));
    p->my = malloc(PLOT_MARKS * sizeof(double));
    p->imp = calloc((size_t)(sc->ncontact > 0 ? sc->ncontact : 1), sizeof(double));
    if (!p->which || !p->t || !p->y || !p->mt || !p->my || !p->imp) {
        pd_scene_plot_free(p);
        return pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
    }
    for (int k = 0; k < p->ncurves; k++) /* evenly over the row, both ends included */
        p->which[k] = p->ncurves > 1 ? (int)((long)k * (sc->nstruct - 1) / (p->ncurves - 1)) : 0;
    *out = p;
    return PD_OK;
}

/* Top-storey displacement of structure s in a sample. */
static double top(const pd_scene *sc, const pd_scene_sample *s, int st)
{
    return s->x[sc->st[st].dof + sc->st[st].storeys - 1];
}

int pd_scene_plot_sample(const pd_scene_sample *s, void *ctx)
{
    pd_scene_plot *p = ctx;
    const pd_scene *sc = p->sc;
    for (int a = 0; a < sc->ncontact && s->impulse; a++)
        if (s->impulse[a] > 0.0 && p->nmarks < PLOT_MARKS) {
            const pd_contact *ct = &sc->ct[a];
            int st = ct->a != PD_WALL ? ct->a : ct->b;
            p->mt[p->nmarks] = s->t;
            p->my[p->nmarks++] = top(sc, s, st);
        }
    if (p->seen++ % p->stride || p->np >= PLOT_POINTS + 2)
        return 0;
    p->t[p->np] = s->t;
    for (int k = 0; k < p->ncurves; k++)
        p->y[(size_t)k * (PLOT_POINTS + 2) + p->np] = top(sc, s, p->which[k]);
    p->np++;
    return 0;
}

int pd_scene_plot_draw(pd_scene_plot *p, const char *png, const char *title, pd_err *err)
{
    pd_curve cv[PLOT_CURVES + 1];
    char labels[PLOT_CURVES][PD_NAME_MAX + 24];
    int nc = 0;
    for (int k = 0; k < p->ncurves; k++, nc++) {
        const pd_structure *st = &p->sc->st[p->which[k]];
        if (st->storeys > 1)
            snprintf(labels[k], sizeof labels[k], "%s (storey %d)", st->name, st->storeys);
        else
            snprintf(labels[k], sizeof labels[k], "%s", st->name);
        cv[nc] = (pd_curve){.label = labels[k],
                            .n = (int)p->np,
                            .x = p->t,
                            .y = p->y + (size_t)k * (PLOT_POINTS + 2),
                            .style = PD_CURVE_LINES};
    }
    if (p->nmarks > 0)
        cv[nc++] = (pd_curve){.label = "impacts",
                              .n = (int)p->nmarks,
                              .x = p->mt,
                              .y = p->my,
                              .style = PD_CURVE_POINTS};
    pd_chart ch = {.title = title,
                   .xlabel = "t [s]",
                   .ylabel = "displacement relative to the ground [m]",
                   .ncurves = nc,
                   .curves = cv,
                   .vline = NAN};
    return pd_plot(png, &ch, err);
}
