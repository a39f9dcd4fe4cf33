/* pd_plot.h — (cli) line charts (log or linear axes) drawn by gnuplot into
 * PNG files. */
#ifndef PD_PLOT_H
#define PD_PLOT_H

#include <stdio.h>

#include "pd_core.h"

typedef enum { PD_CURVE_LINESPOINTS = 0, PD_CURVE_LINES = 1, PD_CURVE_POINTS = 2 } pd_curve_style;

typedef struct pd_curve {
    const char *label;
    int n;
    const double *x, *y;
    pd_curve_style style;
} pd_curve;

typedef struct pd_chart {
    const char *title, *xlabel, *ylabel;
    int logx, logy;
    int ncurves;
    const pd_curve *curves;
    double vline;             /* NAN: none; else a vertical marker at x = vline */
    const char *vline_label;
    double slope_ref;         /* 0: none; else a dashed guide of this log-log slope */
} pd_chart;

/* Draw the chart into png (written to a temporary name, renamed on
 * success).  PD_EIO when gnuplot is missing or fails. */
int pd_plot(const char *png, const pd_chart *chart, pd_err *err);

/* Any figure: data_fn writes the data file (0 ok), script_fn the gnuplot
 * script that reads it and writes png_tmp; the PNG is renamed into place
 * when gnuplot succeeded.  PD_EIO otherwise. */
int pd_plot_with(const char *png, int (*data_fn)(FILE *f, const void *ctx),
                 void (*script_fn)(FILE *g, const char *data, const char *png_tmp,
                                   const void *ctx),
                 const void *ctx, pd_err *err);

#endif
