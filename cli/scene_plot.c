/* scene_plot.c — (cli) the displacement histories of a scene run (or of the
 * oscillator as a one-structure scene) drawn by gnuplot, with every wall
 * drawn where it stands and every impact marked once, at the time of the
 * sample that reports it, on the curve of the storey where it happened.
 *
 * A few structures with contacts below their top (at most PLOT_PANELS) get
 * a panel each with the storeys of their contacts and the top; otherwise
 * the top storeys of up to PLOT_STRUCTS structures, evenly spread over the
 * row, PLOT_GROUP to a panel (an impact at a storey not drawn is then
 * counted in the key but not marked).  A last panel draws the gaps of the contacts
 * (PLOT_GAPS at most, evenly over the scene's), zero where a contact is
 * closed. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_plot.h"
#include "pd_scene_out.h"

#define PLOT_STRUCTS 12  /* most structures in one panel */
#define PLOT_PANELS 4    /* most structures drawn a panel each */
#define PLOT_STOREYS 8   /* most storeys of one structure drawn */
#define PLOT_POINTS 2000 /* points per curve (the samples are decimated) */
#define PLOT_MARKS 4000  /* most impacts marked */
#define PLOT_GAPS 8      /* most contacts whose gaps are drawn */
#define PLOT_GROUP 4     /* most structures' tops in one panel */

/* A curve: storey `storey` (1-based) of structure st, in panel `panel`. */
typedef struct plot_curve {
    int st, storey, panel;
} plot_curve;

struct pd_scene_plot {
    const pd_scene *sc;
    int npanels, panel_mode; /* panel_mode: a panel per structure */
    int ncurves;
    plot_curve *cv;
    long stride, seen, np;
    double *t, *y; /* np times; ncurves x (PLOT_POINTS + 2) displacements */
    long nmarks;
    double *mt, *my; /* marks: time and displacement of the storey hit */
    int *mp;         /* the panel of each mark */
    long impacts[PLOT_PANELS > 1 ? PLOT_PANELS : 1]; /* impacts of each panel's contacts */
    long impacts_all;                                /* of the run */
    int ngaps;                                       /* contacts whose gaps are drawn */
    int gap_of[PLOT_GAPS];                           /* their indices */
    double *g;                                       /* ngaps x (PLOT_POINTS + 2) gaps */
};

void pd_scene_plot_free(pd_scene_plot *p)
{
    if (!p)
        return;
    free(p->cv);
    free(p->t);
    free(p->y);
    free(p->mt);
    free(p->my);
    free(p->mp);
    free(p->g);
    free(p);
}

/* The storey (1-based) of structure s that contact c touches, 0 if none. */
static int contact_storey(const pd_contact *c, int s)
{
    return c->a == s ? c->level_a : c->b == s ? c->level_b : 0;
}

/* Does some contact touch a storey below its structure's top? */
static int contacts_below_top(const pd_scene *sc)
{
    for (int a = 0; a < sc->ncontact; a++) {
        const pd_contact *c = &sc->ct[a];
        if ((c->a != PD_WALL && c->level_a < sc->st[c->a].storeys) ||
            (c->b != PD_WALL && c->level_b < sc->st[c->b].storeys))
            return 1;
    }
    return 0;
}

/* The curves of structure s in panel p: its top, then the storeys of its
 * contacts from the highest down, PLOT_STOREYS at most; 0 or -1. */
static int panel_curves(pd_scene_plot *p, int s, int panel)
{
    const pd_scene *sc = p->sc;
    int top = sc->st[s].storeys, kept = 0;
    unsigned char *hit = calloc((size_t)top + 1, 1);
    if (!hit)
        return -1;
    hit[top] = 1;
    for (int a = 0; a < sc->ncontact; a++)
        hit[contact_storey(&sc->ct[a], s)] = 1;
    for (int k = top; k >= 1 && kept < PLOT_STOREYS; k--)
        if (hit[k]) {
            p->cv[p->ncurves++] = (plot_curve){.st = s, .storey = k, .panel = panel};
            kept++;
        }
    free(hit);
    return 0;
}

int pd_scene_plot_open(pd_scene_plot **out, const pd_scene *sc, long expected, pd_err *err)
{
    pd_scene_plot *p = calloc(1, sizeof *p);
    *out = NULL;
    if (!p)
        return pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
    p->sc = sc;
    p->panel_mode = sc->nstruct <= PLOT_PANELS && contacts_below_top(sc);
    p->npanels = p->panel_mode ? sc->nstruct : 1;
    int cap = p->panel_mode ? PLOT_PANELS * PLOT_STOREYS : PLOT_STRUCTS;
    p->stride = expected / PLOT_POINTS + 1;
    p->cv = malloc((size_t)cap * sizeof *p->cv);
    p->t = malloc((PLOT_POINTS + 2) * sizeof(double));
    p->y = malloc((size_t)cap * (PLOT_POINTS + 2) * sizeof(double));
    p->mt = malloc(PLOT_MARKS * sizeof(double));
    p->my = malloc(PLOT_MARKS * sizeof(double));
    p->mp = malloc(PLOT_MARKS * sizeof(int));
    p->ngaps = sc->ncontact < PLOT_GAPS ? sc->ncontact : PLOT_GAPS;
    for (int j = 0; j < p->ngaps; j++) /* evenly over the contacts, both ends */
        p->gap_of[j] = p->ngaps > 1 ? (int)((long)j * (sc->ncontact - 1) / (p->ngaps - 1)) : 0;
    p->g = malloc((size_t)(p->ngaps > 0 ? p->ngaps : 1) * (PLOT_POINTS + 2) * sizeof(double));
    int bad = !p->cv || !p->t || !p->y || !p->mt || !p->my || !p->mp || !p->g;
    if (!bad && p->panel_mode)
        for (int s = 0; s < sc->nstruct && !bad; s++)
            bad = panel_curves(p, s, s) != 0;
    else if (!bad) { /* top storeys, evenly over the row, both ends included */
        p->ncurves = sc->nstruct < PLOT_STRUCTS ? sc->nstruct : PLOT_STRUCTS;
        /* panels of PLOT_GROUP tops at most, as even as they go */
        p->npanels = (p->ncurves + PLOT_GROUP - 1) / PLOT_GROUP;
        for (int k = 0; k < p->ncurves; k++) {
            int s = p->ncurves > 1 ? (int)((long)k * (sc->nstruct - 1) / (p->ncurves - 1)) : 0;
            p->cv[k] = (plot_curve){
                .st = s, .storey = sc->st[s].storeys, .panel = k * p->npanels / p->ncurves};
        }
    }
    if (bad) {
        pd_scene_plot_free(p);
        return pd_err_set(err, PD_ENOMEM, "--plot: out of memory");
    }
    *out = p;
    return PD_OK;
}

/* Displacement of curve k's storey in a sample. */
static double storey_x(const pd_scene *sc, const pd_scene_sample *s, int st, int storey)
{
    return s->x[sc->st[st].dof + storey - 1];
}

/* Mark the impacts contact a reports in sample s on each side drawn. */
static void mark(pd_scene_plot *p, const pd_scene_sample *s, int a)
{
    const pd_contact *c = &p->sc->ct[a];
    int sides[2] = {c->a, c->b};
    p->impacts_all += s->impacts[a];
    for (int k = 0; k < 2; k++) {
        if (sides[k] == PD_WALL)
            continue;
        int storey = contact_storey(c, sides[k]);
        if (p->panel_mode) /* the panel of structure s is panel s */
            p->impacts[sides[k]] += s->impacts[a];
        for (int j = 0; j < p->ncurves; j++) {
            const plot_curve *cv = &p->cv[j];
            if (cv->st != sides[k] || cv->storey != storey)
                continue;
            if (p->nmarks < PLOT_MARKS) {
                p->mt[p->nmarks] = s->t;
                p->my[p->nmarks] = storey_x(p->sc, s, cv->st, storey);
                p->mp[p->nmarks++] = cv->panel;
            }
            break;
        }
    }
}

/* Keep the points at even indices (their samples are the multiples of
 * twice the stride) and double the stride: the curves still reach the end
 * of a run with more samples than expected (the references' events). */
static void halve(pd_scene_plot *p)
{
    long n = (p->np + 1) / 2;
    for (long i = 0; i < n; i++)
        p->t[i] = p->t[2 * i];
    for (int k = 0; k < p->ncurves; k++) {
        double *y = p->y + (size_t)k * (PLOT_POINTS + 2);
        for (long i = 0; i < n; i++)
            y[i] = y[2 * i];
    }
    for (int j = 0; j < p->ngaps; j++) {
        double *gj = p->g + (size_t)j * (PLOT_POINTS + 2);
        for (long i = 0; i < n; i++)
            gj[i] = gj[2 * i];
    }
    p->np = n;
    p->stride *= 2;
}

int pd_scene_plot_sample(const pd_scene_sample *s, void *ctx)
{
    pd_scene_plot *p = ctx;
    const pd_scene *sc = p->sc;
    for (int a = 0; a < sc->ncontact && s->impacts; a++)
        if (s->impacts[a] > 0)
            mark(p, s, a);
    if (p->seen++ % p->stride)
        return 0;
    if (p->np == PLOT_POINTS + 2) /* more samples than expected: every other point kept */
        halve(p);
    p->t[p->np] = s->t;
    for (int k = 0; k < p->ncurves; k++)
        p->y[(size_t)k * (PLOT_POINTS + 2) + p->np] = storey_x(sc, s, p->cv[k].st, p->cv[k].storey);
    for (int j = 0; j < p->ngaps; j++)
        p->g[(size_t)j * (PLOT_POINTS + 2) + p->np] = s->gap ? s->gap[p->gap_of[j]] : NAN;
    p->np++;
    return 0;
}

/* What the script needs besides the plot. */
typedef struct plot_fig {
    const pd_scene_plot *p;
    const char *title;
} plot_fig;

/* The data: a block per curve (t, x), then a block per panel of its marks. */
static int plot_data(FILE *f, const void *ctx)
{
    const pd_scene_plot *p = ((const plot_fig *)ctx)->p;
    for (int k = 0; k < p->ncurves; k++) {
        for (long i = 0; i < p->np; i++)
            fprintf(f, "%.17g %.17g\n", p->t[i], p->y[(size_t)k * (PLOT_POINTS + 2) + i]);
        fputs("\n\n", f);
    }
    for (int q = 0; q < p->npanels; q++) {
        for (long i = 0; i < p->nmarks; i++)
            if (p->mp[i] == q)
                fprintf(f, "%.17g %.17g\n", p->mt[i], p->my[i]);
        fputs("\n\n", f);
    }
    for (int j = 0; j < p->ngaps; j++) { /* the gaps' blocks, after the marks' */
        for (long i = 0; i < p->np; i++)
            fprintf(f, "%.17g %.17g\n", p->t[i], p->g[(size_t)j * (PLOT_POINTS + 2) + i]);
        fputs("\n\n", f);
    }
    return ferror(f) ? -1 : 0;
}

/* Marks in panel q. */
static long panel_marks(const pd_scene_plot *p, int q)
{
    long n = 0;
    for (long i = 0; i < p->nmarks; i++)
        n += p->mp[i] == q;
    return n;
}

/* The walls of panel q: a dashed black line where each wall stands (the
 * displacement at which its gap closes), keyed with the gap. */
static void plot_walls(FILE *g, const pd_scene_plot *p, int q)
{
    const pd_scene *sc = p->sc;
    for (int a = 0; a < sc->ncontact; a++) {
        const pd_contact *c = &sc->ct[a];
        int s = c->a == PD_WALL ? c->b : c->b == PD_WALL ? c->a : -1, drawn = 0;
        for (int j = 0; j < p->ncurves && s >= 0; j++)
            drawn |= p->cv[j].st == s && p->cv[j].panel == q;
        if (!drawn)
            continue;
        char key[PD_NAME_MAX + 64], at[32] = "";
        int storey = contact_storey(c, s);
        if (sc->st[s].storeys > 1)
            snprintf(at, sizeof at, " at storey %d", storey);
        if (p->panel_mode || sc->nstruct == 1)
            snprintf(key, sizeof key, "wall%s (gap %.3g m)", at, c->gap);
        else
            snprintf(key, sizeof key, "wall of %s%s (gap %.3g m)", sc->st[s].name, at, c->gap);
        /* black in a structure's own panel; in one panel for several
         * structures, in its structure's colour: the wall binds that one */
        if (p->panel_mode || sc->nstruct == 1)
            fprintf(g, ", %.17g with lines lw 1.5 dt 2 lc rgb 'black' title ",
                    c->a == PD_WALL ? -c->gap : c->gap);
        else
            fprintf(g, ", %.17g with lines lw 1.5 dt 2 lt %d title ",
                    c->a == PD_WALL ? -c->gap : c->gap, s + 1);
        pd_plot_literal(g, key);
    }
}

/* One panel's plot command: its curves, walls and marks. */
static void plot_panel(FILE *g, const char *data, const pd_scene_plot *p, int q)
{
    const pd_scene *sc = p->sc;
    int first = 1;
    fputs("plot ", g);
    for (int k = 0; k < p->ncurves; k++) {
        const plot_curve *cv = &p->cv[k];
        char key[PD_NAME_MAX + 32];
        if (cv->panel != q)
            continue;
        if (p->panel_mode)
            snprintf(key, sizeof key, "storey %d%s", cv->storey,
                     cv->storey == sc->st[cv->st].storeys ? " (top)" : "");
        else if (sc->st[cv->st].storeys > 1)
            snprintf(key, sizeof key, "%s (storey %d)", sc->st[cv->st].name, cv->storey);
        else
            snprintf(key, sizeof key, "%s", sc->st[cv->st].name);
        fputs(first ? "" : ", ", g);
        first = 0;
        pd_plot_text(g, data);
        /* one colour per storey in every panel, per structure in one panel */
        fprintf(g, " index %d with lines lw 1.5 lt %d title ", k,
                p->panel_mode ? cv->storey : cv->st + 1);
        pd_plot_literal(g, key);
    }
    plot_walls(g, p, q);
    if (panel_marks(p, q) > 0) {
        char key[64];
        if (!p->panel_mode && p->npanels > 1) /* a group's: the marks on its curves */
            snprintf(key, sizeof key, "impacts marked (%ld)", panel_marks(p, q));
        else
            snprintf(key, sizeof key, "impacts (%ld)",
                     p->panel_mode ? p->impacts[q] : p->impacts_all);
        fputs(", ", g);
        pd_plot_text(g, data);
        fprintf(g, " index %d with points pt 7 ps 0.8 lc rgb 'black' title ", p->ncurves + q);
        pd_plot_literal(g, key);
    }
    fputc('\n', g);
}

/* The gaps' panel: each drawn contact's gap against t, closed at 0. */
static void plot_gaps(FILE *g, const char *data, const pd_scene_plot *p)
{
    const pd_scene *sc = p->sc;
    fputs("set title 'gaps (0: in contact)'\nset xlabel 't [s]'\nset ylabel 'gap [m]'\n"
          "plot 0 with lines lw 1 lc rgb 'black' title ''",
          g);
    for (int j = 0; j < p->ngaps; j++) {
        const pd_contact *c = &sc->ct[p->gap_of[j]];
        char key[2 * PD_NAME_MAX + 32];
        snprintf(key, sizeof key, "%s-%s@%d", c->a == PD_WALL ? "wall" : sc->st[c->a].name,
                 c->b == PD_WALL ? "wall" : sc->st[c->b].name,
                 c->a == PD_WALL ? c->level_b : c->level_a);
        fputs(", ", g);
        pd_plot_text(g, data);
        fprintf(g, " index %d with lines lw 1.2 lt %d title ", p->ncurves + p->npanels + j, j + 1);
        pd_plot_literal(g, key);
    }
    fputc('\n', g);
}

static void plot_script(FILE *g, const char *data, const char *png_tmp, const void *ctx)
{
    const plot_fig *fig = ctx;
    const pd_scene_plot *p = fig->p;
    int gaps = p->ngaps > 0; /* a last panel of the gaps */
    fprintf(g, "set terminal pngcairo size 900,%d enhanced font 'sans,10'\n",
            (p->panel_mode ? 60 + 260 * p->npanels : 650) + (gaps ? 260 : 0));
    pd_plot_style(g);
    fputs("set output ", g);
    pd_plot_text(g, png_tmp);
    fputs("\nset grid\nset autoscale xfix\n", g); /* the time axis: the run, no more */
    if (!p->panel_mode && p->npanels == 1) {
        if (gaps) { /* the displacements over 70 % of the height, the gaps below */
            fputs("set multiplot\nset size 1,0.7\nset origin 0,0.3\nset key outside right top "
                  "vertical font ',9'\nset rmargin 24\nset lmargin 10\nset xlabel ''\n"
                  "set title ",
                  g);
            pd_plot_literal(g, fig->title);
            fputc('\n', g);
        } else {
            fputs("set key below font ',9'\nset title ", g);
            pd_plot_literal(g, fig->title);
            fputs("\nset xlabel 't [s]'\n", g);
        }
        fputs("set ylabel 'displacement relative to the ground [m]'\n", g);
        plot_panel(g, data, p, 0);
        if (gaps) {
            fputs("set size 1,0.3\nset origin 0,0\n", g);
            plot_gaps(g, data, p);
            fputs("unset multiplot\n", g);
        }
        return;
    }
    fputs("set multiplot layout ", g);
    fprintf(g, "%d,1 title ", p->npanels + gaps);
    pd_plot_literal(g, fig->title);
    fputs("\nset key outside right top vertical font ',9'\nset lmargin 10\nset rmargin 24\n"
          "set ylabel 'x [m]'\n",
          g);
    for (int q = 0; q < p->npanels; q++) {
        char name[2 * PD_NAME_MAX + 8];
        if (p->panel_mode)
            snprintf(name, sizeof name, "%s", p->sc->st[q].name);
        else { /* the first and last structures of the group */
            int a = -1, b = -1;
            for (int k = 0; k < p->ncurves; k++)
                if (p->cv[k].panel == q) {
                    a = a < 0 ? p->cv[k].st : a;
                    b = p->cv[k].st;
                }
            snprintf(name, sizeof name, "%s ... %s", a >= 0 ? p->sc->st[a].name : "",
                     b >= 0 ? p->sc->st[b].name : "");
        }
        fputs("set title ", g);
        pd_plot_literal(g, name);
        fprintf(g, "\nset xlabel '%s'\n", q + 1 == p->npanels && !gaps ? "t [s]" : "");
        plot_panel(g, data, p, q);
    }
    if (gaps)
        plot_gaps(g, data, p);
    fputs("unset multiplot\n", g);
}

int pd_scene_plot_draw(pd_scene_plot *p, const char *png, const char *title, pd_err *err)
{
    plot_fig fig = {.p = p, .title = title};
    return pd_plot_with(png, plot_data, plot_script, &fig, err);
}
