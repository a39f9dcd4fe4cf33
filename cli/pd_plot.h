/* pd_plot.h — (cli) line charts (log or linear axes) drawn by gnuplot into
 * PNG files. */
#ifndef PD_PLOT_H
#define PD_PLOT_H

#include <stdio.h>

#include "pd_core.h"

typedef enum {
    PD_CURVE_LINESPOINTS = 0,
    PD_CURVE_LINES = 1,
    PD_CURVE_POINTS = 2, /* small dots: a scatter of many */
    PD_CURVE_MARKER = 3, /* large diamonds: one or a few points to find at a glance */
    PD_CURVE_FAINT = 4   /* thin grey lines: the members behind a statistic */
} pd_curve_style;

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
    double vline; /* NAN: none; else a vertical marker at x = vline */
    const char *vline_label;
    double slope_ref; /* 0: none; else a dashed guide of this log-log slope */
} pd_chart;

/* Draw the chart into png (gnuplot writes a private temporary file, which
 * is then moved into place whole).  PD_EIO when gnuplot is missing or fails,
 * or png cannot be written. */
int pd_plot(const char *png, const pd_chart *chart, pd_err *err);

/* Any figure: data_fn writes the data file (0 ok), script_fn the gnuplot
 * script that reads data and writes png_tmp.  Both paths are private
 * temporary names; the user's png never reaches gnuplot.  The PNG is moved
 * to png (renamed, or copied and renamed across file systems) when gnuplot
 * succeeded and wrote a PNG; no temporary is left either way.  PD_EIO
 * otherwise. */
typedef int pd_plot_data_fn(FILE *f, const void *ctx);
typedef void pd_plot_script_fn(FILE *g, const char *data, const char *png_tmp, const void *ctx);
int pd_plot_with(const char *png, pd_plot_data_fn *data_fn, pd_plot_script_fn *script_fn,
                 const void *ctx, pd_err *err);

/* The settings every figure starts with: UTF-8 text and the palette, line
 * types 1..PD_PLOT_LINETYPES: PD_PLOT_COLOURS distinct colours, solid, then
 * the same dashed, then dash-dotted (a chart of many curves never repeats
 * a style). */
enum { PD_PLOT_COLOURS = 12, PD_PLOT_LINETYPES = 36 };
void pd_plot_style(FILE *g);

/* Write s (NULL: "") into a gnuplot script as one double-quoted string
 * literal that cannot end early or run anything: '"' and '\\' escaped,
 * '`' and '@' as octal escapes, well-formed UTF-8 as it is, control bytes and
 * any other byte beyond ASCII as '?'.
 * Every text and file name in a script goes through it. */
void pd_plot_text(FILE *g, const char *s);
/* s as a gnuplot string literal shown literally in enhanced text (names:
 * '_', '^', '{', '}', '@', '&', '~' escaped): chart titles and keys. */
void pd_plot_literal(FILE *g, const char *s);

#endif
