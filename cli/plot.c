/* plot.c — charts through gnuplot.  The data, the script and the PNG live
 * in a private temporary folder whose name has only safe characters;
 * gnuplot runs the script without a shell, its output on /dev/null (so no
 * image can ever reach our standard output); the PNG, checked by its
 * signature, is then moved to the user's path whole.  No file name of the
 * user's reaches gnuplot, and every text does as one string literal that
 * cannot escape (pd_plot_text). */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pd_plot.h"

enum { PLOT_ROOT_MAX = 200, PLOT_PATH = PLOT_ROOT_MAX + 64, PLOT_COPY_BUF = 16384 };

/* The private folder and the files in it. */
typedef struct plot_work {
    char dir[PLOT_PATH], data[PLOT_PATH + 16], script[PLOT_PATH + 16], png[PLOT_PATH + 16];
} plot_work;

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

/* The length of the well-formed UTF-8 character of two to four bytes at c
 * (no overlong form, no surrogate, at most U+10FFFF), else 0. */
static int utf8_len(const unsigned char *c)
{
    int n = c[0] >= 0xc2 && c[0] <= 0xdf   ? 2
            : c[0] >= 0xe0 && c[0] <= 0xef ? 3
            : c[0] >= 0xf0 && c[0] <= 0xf4 ? 4
                                           : 0;
    for (int k = 1; k < n; k++)
        if ((c[k] & 0xc0) != 0x80)
            return 0;
    if ((c[0] == 0xe0 && c[1] < 0xa0) || (c[0] == 0xed && c[1] >= 0xa0) ||
        (c[0] == 0xf0 && c[1] < 0x90) || (c[0] == 0xf4 && c[1] >= 0x90))
        return 0;
    return n;
}

/* The byte at *c (a control byte or one of a malformed sequence: '?') or
 * the whole UTF-8 character there (the scripts say `set encoding utf8`);
 * *c moved to the last byte written. */
static void put_char(FILE *g, const unsigned char **c)
{
    int n = **c >= 0x80 ? utf8_len(*c) : 0;
    if (n) {
        fwrite(*c, 1, (size_t)n, g);
        *c += n - 1;
    } else
        fputc(**c >= 0x20 && **c < 0x7f ? **c : '?', g);
}

/* s as one gnuplot string literal that cannot escape (pd_plot.h). */
void pd_plot_text(FILE *g, const char *s)
{
    fputc('"', g);
    for (const unsigned char *c = (const unsigned char *)(s ? s : ""); *c; c++)
        if (*c == '"' || *c == '\\')
            fprintf(g, "\\%c", *c);
        else if (*c == '`' || *c == '@') /* \140, \100: three digits never take a fourth */
            fprintf(g, "\\%03o", (unsigned)*c);
        else
            put_char(g, &c);
    fputc('"', g);
}

/* s as a gnuplot string literal shown as it is in enhanced text: names
 * (records, structures, files) whose '_' or '^' would otherwise become
 * subscripts and superscripts ("NGA_no_1063" as "NGA_n o_1 063"). */
void pd_plot_literal(FILE *g, const char *s)
{
    fputc('"', g);
    for (const unsigned char *c = (const unsigned char *)(s ? s : ""); *c; c++)
        if (*c == '"' || *c == '\\')
            fprintf(g, "\\\\\\%c", *c); /* a literal backslash or quote */
        else if (strchr("_^{}&~", *c))
            fprintf(g, "\\\\%c", *c);
        else if (*c == '`' || *c == '@')
            fprintf(g, "\\\\\\%03o", (unsigned)*c);
        else
            put_char(g, &c);
    fputc('"', g);
}

/* The colours of the palette: Okabe and Ito's (yellow left out: too pale
 * on white) and six of Paul Tol's muted set, told apart on screen and in
 * print; a curve past the twelfth takes them again with another dash type. */
static const char *const palette[PD_PLOT_COLOURS] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7",
                                                     "#E69F00", "#56B4E9", "#332288", "#882255",
                                                     "#999933", "#44AA99", "#CC6677", "#555555"};

void pd_plot_style(FILE *g)
{
    static const int dash[3] = {1, 2, 4}; /* solid, dashed, dash-dot */
    fputs("set encoding utf8\n", g);
    for (int k = 0; k < PD_PLOT_LINETYPES; k++)
        fprintf(g, "set linetype %d lc rgb '%s' lw 1.5 dt %d pt %d\n", k + 1,
                palette[k % PD_PLOT_COLOURS], dash[k / PD_PLOT_COLOURS], k % 12 + 1);
    fprintf(g, "set linetype cycle %d\n", PD_PLOT_LINETYPES);
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

/* The range of axis y (0: x) fitted to the data with a margin of 4 % of
 * it each side (log: of its decades), and on a log axis spanning less than
 * three decades ticks at 1, 2 and 5 of each decade (gnuplot's default,
 * whole decades, leaves such an axis one or two labels).  include: a value
 * the range must hold (NAN: none). */
static void axis_range(FILE *g, const pd_chart *c, int y, int logscale, double include)
{
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    const char *ax = y ? "y" : "x";
    for (int k = 0; k < c->ncurves; k++)
        for (int i = 0; i < c->curves[k].n; i++) {
            double v = y ? c->curves[k].y[i] : c->curves[k].x[i];
            if (isfinite(v) && (!logscale || v > 0.0)) {
                lo = fmin(lo, v);
                hi = fmax(hi, v);
            }
        }
    if (isfinite(include) && (!logscale || include > 0.0)) {
        lo = fmin(lo, include);
        hi = fmax(hi, include);
    }
    if (!(lo <= hi)) /* no data: gnuplot's own */
        return;
    if (logscale) {
        double span = log10(hi / lo), m = pow(10.0, 0.04 * (span > 0.0 ? span : 1.0));
        fprintf(g, "set %srange [%.17g:%.17g]\n", ax, lo / m, hi * m);
        if (span < 3.0) {
            fprintf(g, "set format %s '%%g'\nset %stics (", ax, ax);
            int first = 1;
            for (int e = (int)floor(log10(lo / m)); e <= (int)ceil(log10(hi * m)); e++)
                for (int j = 0; j < 3; j++) {
                    double t = (j == 0 ? 1.0 : j == 1 ? 2.0 : 5.0) * pow(10.0, e);
                    if (t >= lo / m && t <= hi * m) {
                        fprintf(g, "%s%.3g", first ? "" : ", ", t);
                        first = 0;
                    }
                }
            fputs(")\n", g);
        }
    } else {
        double pad = 0.04 * (hi > lo ? hi - lo : fabs(hi) > 0.0 ? fabs(hi) : 1.0);
        fprintf(g, "set %srange [%.17g:%.17g]\n", ax, lo - pad, hi + pad);
    }
}

/* The chart's gnuplot script, reading data, writing png_tmp. */
static void chart_script(FILE *g, const char *data, const char *png_tmp, const void *ctx)
{
    const pd_chart *c = ctx;
    fprintf(g, "set terminal pngcairo size 1100,650 enhanced font 'sans,11'\n");
    pd_plot_style(g);
    fputs("set output ", g);
    pd_plot_text(g, png_tmp);
    /* the key right of the chart, clear of the axis labels, in a smaller font
     * as the curves grow; the axes fit to the data (no padding to whole
     * decades), a margin inside them so that no curve touches the frame */
    fprintf(g, "\nset grid\nset key outside right top vertical font ',%d' spacing 0.9\n",
            c->ncurves > 6 ? 9 : 10);
    if (c->logx)
        fputs("set logscale x\nset format x '10^{%L}'\n", g);
    if (c->logy)
        fputs("set logscale y\nset format y '10^{%L}'\n", g);
    axis_range(g, c, 0, c->logx, isfinite(c->vline) ? c->vline : NAN);
    axis_range(g, c, 1, c->logy, NAN);
    fputs("set title ", g);
    pd_plot_literal(g, c->title);
    fputs("\nset xlabel ", g);
    pd_plot_text(g, c->xlabel);
    fputs("\nset ylabel ", g);
    pd_plot_text(g, c->ylabel);
    fputc('\n', g);
    if (isfinite(c->vline)) {
        fprintf(g, "set arrow from %.17g, graph 0 to %.17g, graph 1 nohead dt 3 lc rgb 'black'\n",
                c->vline, c->vline);
        fprintf(g, "set label ");
        pd_plot_literal(g, c->vline_label ? c->vline_label : "");
        fprintf(g, " at %.17g, graph 0.03 left rotate by 90 offset -0.8,0\n", c->vline);
    }
    fputs("plot ", g);
    for (int k = 0; k < c->ncurves; k++) {
        static const char *const styles[] = {"linespoints lw 2", "lines lw 1.5",
                                             "points pt 7 ps 0.8", "points pt 13 ps 2.2",
                                             "lines lw 1 dt 1 lc rgb 'gray65'"};
        fputs(k ? ", " : "", g);
        pd_plot_text(g, data);
        fprintf(g, " index %d with %s title ", k, styles[c->curves[k].style]);
        pd_plot_literal(g, c->curves[k].label);
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

/* Where the private folder goes: $TMPDIR when it is an absolute path of
 * safe characters that fits, else /tmp. */
static const char *tmp_root(void)
{
    static const char safe[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789/._-";
    const char *t = getenv("TMPDIR");
    size_t n = t ? strlen(t) : 0;
    return t && t[0] == '/' && n <= PLOT_ROOT_MAX && strspn(t, safe) == n ? t : "/tmp";
}

/* Create the private folder (mode 0700) under root and name its files (0
 * ok, errno set otherwise). */
static int work_open(plot_work *w, const char *root)
{
    snprintf(w->dir, sizeof w->dir, "%s/pound_plotXXXXXX", root);
    if (!mkdtemp(w->dir))
        return -1;
    snprintf(w->data, sizeof w->data, "%s/data", w->dir);
    snprintf(w->script, sizeof w->script, "%s/plot.gp", w->dir);
    snprintf(w->png, sizeof w->png, "%s/plot.png", w->dir);
    return 0;
}

/* Remove the private folder and whatever is left in it. */
static void work_close(const plot_work *w)
{
    unlink(w->data);
    unlink(w->script);
    unlink(w->png);
    rmdir(w->dir);
}

/* The data file, written by data_fn (0 ok). */
static int write_data_file(const plot_work *w, pd_plot_data_fn *data_fn, const void *ctx)
{
    FILE *f = fopen(w->data, "w");
    if (!f)
        return -1;
    int bad = data_fn(f, ctx) || ferror(f);
    return fclose(f) != 0 || bad ? -1 : 0;
}

/* The script file, written by script_fn (0 ok). */
static int write_script_file(const plot_work *w, pd_plot_script_fn *script_fn, const void *ctx)
{
    FILE *g = fopen(w->script, "w");
    if (!g)
        return -1;
    script_fn(g, w->data, w->png, ctx);
    int bad = ferror(g);
    return fclose(g) != 0 || bad ? -1 : 0;
}

/* Run gnuplot on the script file, without a shell, its standard streams on
 * /dev/null; a script file makes any error end it with a failure.  0 when
 * it succeeded, 1 when it failed, -1 when it could not be started. */
static int run_gnuplot(const char *script)
{
    extern char **environ;
    char prog[] = "gnuplot", *argv[] = {prog, (char *)script, NULL};
    posix_spawn_file_actions_t fa;
    pid_t pid;
    int st = 0;
    if (posix_spawn_file_actions_init(&fa))
        return -1;
    int bad = posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0) ||
              posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0) ||
              posix_spawn_file_actions_addopen(&fa, 2, "/dev/null", O_WRONLY, 0) ||
              posix_spawnp(&pid, prog, &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (bad)
        return -1;
    while (waitpid(pid, &st, 0) < 0)
        if (errno != EINTR)
            return 1;
    if (WIFEXITED(st) && WEXITSTATUS(st) == 127)
        return -1; /* the exec failed in the child */
    return WIFEXITED(st) && WEXITSTATUS(st) == 0 ? 0 : 1;
}

/* Does path hold a PNG (its eight signature bytes)? */
static int is_png(const char *path)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8];
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(head, 1, sizeof head, f) : 0;
    if (f)
        fclose(f);
    return n == sizeof head && !memcmp(head, sig, sizeof sig);
}

/* Copy all of file descriptor in to out (0 ok, -1 with errno). */
static int copy_fd(int in, int out)
{
    char buf[PLOT_COPY_BUF];
    for (;;) {
        ssize_t n = read(in, buf, sizeof buf);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return n < 0 ? -1 : 0;
        for (ssize_t off = 0; off < n;) {
            ssize_t put = write(out, buf + off, (size_t)(n - off));
            if (put < 0 && errno == EINTR)
                continue;
            if (put <= 0)
                return -1;
            off += put;
        }
    }
}

/* Copy src to a new temporary beside dst (src's permissions), flush it to
 * disk and rename it over dst: dst appears whole or not at all (0 ok; -1
 * with errno, the temporary removed). */
static int copy_into_place(const char *src, const char *dst)
{
    char tmp[4096];
    struct stat st;
    if (snprintf(tmp, sizeof tmp, "%s.XXXXXX", dst) >= (int)sizeof tmp) {
        errno = ENAMETOOLONG;
        return -1;
    }
    int in = open(src, O_RDONLY), out = in >= 0 ? mkstemp(tmp) : -1;
    int bad = out < 0 || fstat(in, &st) || fchmod(out, st.st_mode & 0777) || copy_fd(in, out) ||
              fsync(out);
    int saved = errno;
    if (out >= 0 && close(out) && !bad) {
        bad = 1;
        saved = errno;
    }
    if (in >= 0)
        close(in);
    if (!bad && rename(tmp, dst)) {
        bad = 1;
        saved = errno;
    }
    if (bad && out >= 0)
        unlink(tmp);
    errno = saved;
    return bad ? -1 : 0;
}

/* Move src to dst: a rename on one file system, else copy_into_place (0
 * ok; -1 with errno). */
static int move_into_place(const char *src, const char *dst)
{
    if (rename(src, dst) == 0)
        return 0;
    return errno == EXDEV ? copy_into_place(src, dst) : -1;
}

/* POUND_PLOT_SCRIPT=1: the script and its data kept beside the chart, as
 * F.gp and F.dat for F.png (to read or adapt; the paths in the script are
 * the temporary ones).  0, or PD_EIO. */
static int keep_script(const plot_work *w, const char *png, pd_err *err)
{
    const char *keep = getenv("POUND_PLOT_SCRIPT");
    char gp[4096], dat[4096];
    size_t n = strlen(png);
    if (!keep || strcmp(keep, "1") || n < 4 || n + 1 > sizeof gp)
        return PD_OK;
    snprintf(gp, sizeof gp, "%.*s.gp", (int)(n - 4), png);
    snprintf(dat, sizeof dat, "%.*s.dat", (int)(n - 4), png);
    if (copy_into_place(w->script, gp) || copy_into_place(w->data, dat))
        return pd_err_set(err, PD_EIO, "--plot %s: POUND_PLOT_SCRIPT: cannot write %s: %s", png, gp,
                          strerror(errno));
    return PD_OK;
}

/* The steps in the private folder w: data, script, gnuplot, the PNG
 * checked and moved to png. */
static int draw(const plot_work *w, const char *png, pd_plot_data_fn *data_fn,
                pd_plot_script_fn *script_fn, const void *ctx, pd_err *err)
{
    if (write_data_file(w, data_fn, ctx) || write_script_file(w, script_fn, ctx))
        return pd_err_set(err, PD_EIO, "--plot %s: cannot write the temporary files in %s", png,
                          w->dir);
    int g = run_gnuplot(w->script);
    if (g < 0)
        return pd_err_set(err, PD_EIO, "--plot %s: cannot run gnuplot (is gnuplot installed?)",
                          png);
    if (g > 0 || !is_png(w->png))
        return pd_err_set(err, PD_EIO, "--plot %s: gnuplot failed", png);
    if (move_into_place(w->png, png))
        return pd_err_set(err, PD_EIO, "--plot %s: cannot write the file: %s", png,
                          strerror(errno));
    return keep_script(w, png, err);
}

int pd_plot_with(const char *png, pd_plot_data_fn *data_fn, pd_plot_script_fn *script_fn,
                 const void *ctx, pd_err *err)
{
    plot_work w;
    if (work_open(&w, tmp_root()) && work_open(&w, "/tmp")) /* a stale $TMPDIR: /tmp */
        return pd_err_set(err, PD_EIO, "--plot: cannot create a temporary folder in /tmp: %s",
                          strerror(errno));
    int rc = draw(&w, png, data_fn, script_fn, ctx, err);
    work_close(&w);
    return rc;
}
