/* plot.c — charts through gnuplot: data in a temporary file, a script on
 * gnuplot's standard input, the PNG renamed into place when it succeeded. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_plot.h"

/* One block per curve, blocks separated by two blank lines (gnuplot index). */
static int write_data(FILE *f, const pd_chart *c)
{
    for (int k = 0; k < c->ncurves; k++) {
        for (int i = 0; i < c->curves[k].n; i++)
            if (isfinite(c->curves[k].x[i]) && isfinite(c->curves[k].y[i]) &&
                (!c->logy || c->curves[k].y[i] > 0))
                fprintf(f, "%.17g %.17g\n", c->curves[k].x[i], c->curves[k].y[i]);
        fputs("\n\n", f);
    }
    return ferror(f) ? -1 : 0;
}

/* Gnuplot text escaping for labels: quotes only. */
static void quoted(FILE *g, const char *s)
{
    fputc('"', g);
    for (; s && *s; s++)
        fputc(*s == '"' ? '\'' : *s, g);
    fputc('"', g);
}

/* A guide line of slope s through the first point of the first curve. */
static void slope_guide(FILE *g, const pd_chart *c)
{
    const pd_curve *cv = &c->curves[0];
    if (c->slope_ref == 0.0 || cv->n < 1 || !(cv->x[0] > 0) || !(cv->y[0] > 0))
        return;
    fprintf(g, ", %.17g*(x/%.17g)**%g with lines dt 2 lc rgb 'gray' title 'slope %g'", cv->y[0],
            cv->x[0], c->slope_ref, c->slope_ref);
}

/* The chart's gnuplot script, reading data, writing png_tmp. */
static void chart_script(FILE *g, const char *data, const char *png_tmp, const void *ctx)
{
    const pd_chart *c = ctx;
    fprintf(g, "set terminal pngcairo size 900,650 enhanced font 'sans,11'\n");
    fprintf(g, "set output '%s'\nset grid\nset key outside right top\n", png_tmp);
    if (c->logx)
        fputs("set logscale x\nset format x '10^{%L}'\n", g);
    if (c->logy)
        fputs("set logscale y\nset format y '10^{%L}'\n", g);
    fputs("set title ", g);
    quoted(g, c->title);
    fputs("\nset xlabel ", g);
    quoted(g, c->xlabel);
    fputs("\nset ylabel ", g);
    quoted(g, c->ylabel);
    fputc('\n', g);
    if (isfinite(c->vline)) {
        double lo = c->vline, hi = c->vline; /* the marker inside the x range */
        for (int k = 0; k < c->ncurves; k++)
            for (int i = 0; i < c->curves[k].n; i++)
                if (!c->logx || c->curves[k].x[i] > 0.0) {
                    lo = fmin(lo, c->curves[k].x[i]);
                    hi = fmax(hi, c->curves[k].x[i]);
                }
        if (c->logx)
            fprintf(g, "set xrange [%.17g:%.17g]\n", lo / 2.0, hi * 2.0);
        else
            fprintf(g, "set xrange [%.17g:%.17g]\n", lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo));
        fprintf(g, "set arrow from %.17g, graph 0 to %.17g, graph 1 nohead dt 3 lc rgb 'black'\n",
                c->vline, c->vline);
        fprintf(g, "set label ");
        quoted(g, c->vline_label ? c->vline_label : "");
        fprintf(g, " at %.17g, graph 0.05 right offset -0.5,0\n", c->vline);
    }
    fputs("plot ", g);
    for (int k = 0; k < c->ncurves; k++) {
        static const char *const styles[] = {"linespoints lw 2", "lines lw 1.5",
                                             "points pt 7 ps 0.8"};
        fprintf(g, "%s'%s' index %d with %s title ", k ? ", " : "", data, k,
                styles[c->curves[k].style]);
        quoted(g, c->curves[k].label);
    }
    slope_guide(g, c);
    fputc('\n', g);
}

/* The chart's data: one block per curve. */
static int chart_data(FILE *f, const void *ctx)
{
    return write_data(f, ctx);
}

int pd_plot(const char *png, const pd_chart *chart, pd_err *err)
{
    return pd_plot_with(png, chart_data, chart_script, chart, err);
}

int pd_plot_with(const char *png, int (*data_fn)(FILE *f, const void *ctx),
                 void (*script_fn)(FILE *g, const char *data, const char *png_tmp,
                                   const void *ctx),
                 const void *ctx, pd_err *err)
{
    char data[] = "/tmp/pound_plotXXXXXX", tmp[4096];
    int fd = mkstemp(data), rc = -1;
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) {
        if (fd >= 0)
            close(fd);
        return pd_err_set(err, PD_EIO, "--plot: cannot create a temporary data file");
    }
    int bad = data_fn(f, ctx);
    if (fclose(f) != 0 || bad)
        goto done;
    if (snprintf(tmp, sizeof tmp, "%s.tmp%ld.png", png, (long)getpid()) >= (int)sizeof tmp)
        goto done;
    FILE *g = popen("gnuplot 2>/dev/null", "w");
    rc = g ? 0 : -1;
    if (g) {
        script_fn(g, data, tmp, ctx);
        rc = pclose(g) == 0 ? 0 : -1;
    }
    if (rc == 0 && access(tmp, R_OK) == 0 && rename(tmp, png) == 0)
        rc = 0;
    else {
        rc = -1;
        unlink(tmp);
    }
done:
    unlink(data);
    return rc ? pd_err_set(err, PD_EIO, "--plot %s: gnuplot failed (is gnuplot installed?)", png)
              : PD_OK;
}
