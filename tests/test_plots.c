/* test_plots.c — --plot never hands gnuplot a file name or a text as script:
 * output names with quotes, backslashes and bytes beyond ASCII; structure,
 * scene and record names built to inject commands; a failed plot writes
 * nothing to standard output and leaves no temporary file behind. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pd_test.h"

/* A scratch folder with a tmp/ subfolder that pound uses as TMPDIR. */
typedef struct plot_dir {
    char dir[64], tmp[96], env[112];
} plot_dir;

/* Is gnuplot there (and pound)?  Skips the case otherwise. */
static int have_tools(pd_test_ctx *ctx)
{
    const char *gp[] = {"gnuplot", "--version", NULL};
    proc_out g;
    if (!pd_test_have_pound(ctx))
        return 0;
    int ok = pd_test_spawn(gp, NULL, &g) == 0;
    pd_test_proc_free(&g);
    if (!ok)
        pd_test_skip(ctx, "gnuplot not installed");
    return ok;
}

/* Make the scratch folder /tmp/pd_plXXXXXX (short: scene names spell it)
 * and its tmp/ (0 ok). */
static int dir_open(pd_test_ctx *ctx, plot_dir *d)
{
    snprintf(d->dir, sizeof d->dir, "/tmp/pd_plXXXXXX");
    if (!CHECK(ctx, mkdtemp(d->dir) != NULL, "mkdtemp"))
        return -1;
    snprintf(d->tmp, sizeof d->tmp, "%s/tmp", d->dir);
    snprintf(d->env, sizeof d->env, "TMPDIR=%s", d->tmp);
    return CHECK(ctx, mkdir(d->tmp, 0700) == 0, "mkdir %s", d->tmp) ? 0 : -1;
}

/* Remove the scratch folder (two levels). */
static void dir_close(const plot_dir *d)
{
    pd_test_rm_dir(d->tmp);
    pd_test_rm_dir(d->dir);
}

/* Run pound with args (NULL-terminated) and env ("NAME=value") added. */
static int run_pound_env(const pd_test_ctx *ctx, const char *env, const char *const *args,
                         proc_out *r)
{
    const char *argv[40];
    int n = 0;
    argv[n++] = ctx->pound;
    for (; args[n - 1] && n < 39; n++)
        argv[n] = args[n - 1];
    argv[n] = NULL;
    return pd_test_spawn(argv, env, r);
}

/* Run pound with args (NULL-terminated) and TMPDIR set to the tmp/ folder. */
static int run_pound(const pd_test_ctx *ctx, const plot_dir *d, const char *const *args,
                     proc_out *r)
{
    return run_pound_env(ctx, d->env, args, r);
}

/* Does path exist? */
static int exists(const char *path)
{
    return access(path, F_OK) == 0;
}

/* Does path hold a PNG (its eight signature bytes)? */
static int is_png(const char *path)
{
    unsigned char sig[8] = {0};
    FILE *f = fopen(path, "rb");
    size_t n = f ? fread(sig, 1, sizeof sig, f) : 0;
    if (f)
        fclose(f);
    return n == 8 && !memcmp(sig, "\x89PNG\r\n\x1a\n", 8);
}

/* The checks every successful plot shares: exit 0, the PNG under exactly
 * png, no injected file, no temporary left in TMPDIR or next to png. */
static void check_plotted(pd_test_ctx *ctx, const plot_dir *d, const proc_out *r, const char *png,
                          int entries)
{
    char pwned[128];
    snprintf(pwned, sizeof pwned, "%s/pwned", d->dir);
    CHECK(ctx, !exists(pwned), "gnuplot ran an injected command (%s exists)", pwned);
    CHECK(ctx, r->status == 0, "exit %d: %s", r->status, r->err);
    CHECK(ctx, is_png(png), "no PNG under the name '%s'", png);
    CHECK(ctx, pd_test_dir_entries(d->tmp) == 0, "%d temporaries left in TMPDIR",
          pd_test_dir_entries(d->tmp));
    CHECK(ctx, pd_test_dir_entries(d->dir) == entries, "%d entries in %s, expected %d",
          pd_test_dir_entries(d->dir), d->dir, entries);
}

/* Make the folders on the way to path (the folders of an odd name). */
static int make_parents(const char *path, char (*made)[256], int cap)
{
    char buf[256];
    int n = 0;
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = strchr(buf + 1, '/'); p && n < cap; p = strchr(p + 1, '/')) {
        *p = '\0';
        if (mkdir(buf, 0700) == 0)
            snprintf(made[n++], sizeof made[0], "%s", buf);
        *p = '/';
    }
    return n;
}

/* --plot "D/a'; print system('touch D/pwned'); print '.png" (its folders
 * made): the command never runs; the chart lands under that very name. */
static void test_plot_name_injection(pd_test_ctx *ctx)
{
    plot_dir d;
    char png[256], made[8][256];
    if (!have_tools(ctx) || dir_open(ctx, &d))
        return;
    snprintf(png, sizeof png, "%s/a'; print system('touch %s/pwned'); print '.png", d.dir, d.dir);
    const char *args[] = {"simulate", "--pulse", "sine", "--plot", png, NULL};
    proc_out r;
    run_pound(ctx, &d, args, &r); /* first into folders that are not there: an error */
    CHECK(ctx, r.status != 0 && r.out && !strstr(r.out, "\x89PNG"),
          "exit %d into missing folders (PNG on standard output: %d)", r.status,
          r.out && strstr(r.out, "\x89PNG"));
    pd_test_proc_free(&r);
    int nmade = make_parents(png, made, 8);
    CHECK(ctx, nmade == 3, "made %d folders on the way to the name, expected 3", nmade);
    run_pound(ctx, &d, args, &r);
    check_plotted(ctx, &d, &r, png, 2);
    CHECK(ctx, nmade < 1 || pd_test_dir_entries(made[nmade - 1]) == 1,
          "the chart's folder holds %d files, expected the chart only",
          nmade ? pd_test_dir_entries(made[nmade - 1]) : -1);
    pd_test_proc_free(&r);
    unlink(png);
    while (nmade > 0)
        pd_test_rm_dir(made[--nmade]);
    dir_close(&d);
}

/* A name with an apostrophe, a double quote, a backslash and a byte beyond
 * ASCII is a legal POSIX name: the chart is written under it. */
static void test_plot_odd_name(pd_test_ctx *ctx)
{
    plot_dir d;
    char png[256];
    if (!have_tools(ctx) || dir_open(ctx, &d))
        return;
    snprintf(png, sizeof png, "%s/it's \"q\" \\ \xc3\xa9\xff.png", d.dir);
    const char *args[] = {"simulate", "--pulse", "sine", "--plot", png, NULL};
    proc_out r;
    run_pound(ctx, &d, args, &r);
    check_plotted(ctx, &d, &r, png, 2);
    pd_test_proc_free(&r);
    dir_close(&d);
}

/* TMPDIR on another file system (/dev/shm): the chart is copied next to
 * the destination and renamed into place, no temporary left either side. */
static void test_plot_across_file_systems(pd_test_ctx *ctx)
{
    plot_dir d;
    char png[256];
    struct stat a, b;
    if (!have_tools(ctx) || dir_open(ctx, &d))
        return;
    char shm[] = "/dev/shm/pd_plotsXXXXXX";
    if (stat("/dev/shm", &a) || stat(d.dir, &b) || a.st_dev == b.st_dev || !mkdtemp(shm)) {
        pd_test_skip(ctx, "no second file system at /dev/shm");
        dir_close(&d);
        return;
    }
    snprintf(d.env, sizeof d.env, "TMPDIR=%s", shm);
    snprintf(png, sizeof png, "%s/o'clock.png", d.dir);
    const char *args[] = {"simulate", "--pulse", "sine", "--plot", png, NULL};
    proc_out r;
    run_pound(ctx, &d, args, &r);
    check_plotted(ctx, &d, &r, png, 2);
    CHECK(ctx, pd_test_dir_entries(shm) == 0, "%d temporaries left in %s", pd_test_dir_entries(shm),
          shm);
    pd_test_proc_free(&r);
    pd_test_rm_dir(shm);
    dir_close(&d);
}

/* --plot into a missing folder: an error, no PNG bytes on standard output,
 * no file anywhere. */
static void test_plot_missing_dir(pd_test_ctx *ctx)
{
    plot_dir d;
    char png[256];
    if (!have_tools(ctx) || dir_open(ctx, &d))
        return;
    snprintf(png, sizeof png, "%s/nonexistent/x.png", d.dir);
    const char *args[] = {"simulate", "--pulse", "sine", "--plot", png, NULL};
    proc_out r;
    run_pound(ctx, &d, args, &r);
    CHECK(ctx, r.status != 0, "exit %d for a plot into a missing folder", r.status);
    CHECK(ctx, r.out && !strstr(r.out, "\x89PNG"), "PNG bytes on standard output");
    CHECK(ctx, r.err && strstr(r.err, "--plot"), "the error names --plot: %s", r.err);
    CHECK(ctx, pd_test_dir_entries(d.tmp) == 0 && pd_test_dir_entries(d.dir) == 1,
          "files left: %d in TMPDIR, %d in the folder", pd_test_dir_entries(d.tmp),
          pd_test_dir_entries(d.dir));
    pd_test_proc_free(&r);
    dir_close(&d);
}

/* Write text into path (0 ok). */
static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    int ok = f && fputs(text, f) >= 0;
    return (f && fclose(f) == 0 && ok) ? 0 : -1;
}

/* A scene whose structure names carry what gnuplot reads as syntax and
 * names may hold (backticks, @, $, %, ;, parentheses), read from a file
 * whose name (the chart's title) has quotes, a backslash and a command;
 * and the names that would break a writer or a script (a backslash at the
 * end, quotes, commas) refused at load, naming the field. */
static void test_plot_scene_names(pd_test_ctx *ctx)
{
    plot_dir d;
    char scene[512], png[256], json[1024], bad[256];
    if (!have_tools(ctx) || dir_open(ctx, &d))
        return;
    snprintf(
        json, sizeof json, "%s",
        "{\"excitation\": {\"pulse\": \"cosine\", \"dir\": \"+x\", \"ap\": 3.0, \"Tp\": 0.6},\n"
        " \"structures\": [\n"
        "  {\"name\": \"x`touch pwned`\", \"T0\": 0.4, \"xi\": 0.05, \"mass\": 2.0e5},\n"
        "  {\"name\": \"@y $HOME %c;system(x)\", \"T0\": 1.2, \"xi\": 0.05, \"mass\": 1.0e5},\n"
        "  {\"name\": \"say `x` @y\", \"T0\": 0.8, \"xi\": 0.05, \"mass\": 1.0e5}],\n"
        " \"contacts\": [{\"a\": \"x`touch pwned`\", \"b\": \"@y $HOME %c;system(x)\","
        " \"gap\": 0.02, \"eps\": 0.65}],\n"
        " \"tend\": 2.0}\n");
    snprintf(scene, sizeof scene, "%s/sc\"e'ne\\\"; system(\"touch pwned\") \".json", d.dir);
    snprintf(png, sizeof png, "%s/scene.png", d.dir);
    if (!CHECK(ctx, write_text(scene, json) == 0, "cannot write %s", scene)) {
        dir_close(&d);
        return;
    }
    const char *args[] = {"simulate", "--scene", scene, "--plot", png, NULL};
    proc_out r;
    run_pound(ctx, &d, args, &r);
    check_plotted(ctx, &d, &r, png, 3);
    pd_test_proc_free(&r);
    static const char *const refused[] = {"x\\\\", "say \\\"hi\\\"", "it's", "a,b"};
    for (int k = 0; k < 4; k++) {
        snprintf(json, sizeof json,
                 "{\"excitation\": {\"pulse\": \"cosine\", \"ap\": 3.0, \"Tp\": 0.6},\n"
                 " \"structures\": [{\"name\": \"%s\", \"T0\": 0.4}]}\n",
                 refused[k]);
        snprintf(bad, sizeof bad, "%s/bad.json", d.dir);
        if (!CHECK(ctx, write_text(bad, json) == 0, "cannot write %s", bad))
            break;
        const char *bargs[] = {"simulate", "--scene", bad, "--plot", png, NULL};
        run_pound(ctx, &d, bargs, &r);
        CHECK(ctx, r.status == 2 && r.err && strstr(r.err, "structures[0].name: "),
              "name %s: exit %d, %s", refused[k], r.status, r.err ? r.err : "");
        pd_test_proc_free(&r);
        unlink(bad);
    }
    dir_close(&d);
}

/* A two-column text record (t a, m/s^2): one cycle of a sine pulse in 8 s. */
static int write_record(const char *path)
{
    FILE *f = fopen(path, "w");
    for (int i = 0; f && i <= 800; i++) {
        double t = 0.01 * i;
        fprintf(f, "%.2f %.6g\n", t,
                t >= 1.0 && t <= 2.0 ? 3.0 * sin(6.283185307179586 * (t - 1.0)) : 0.0);
    }
    return f && fclose(f) == 0 ? 0 : -1;
}

/* path with every '/' spelled \057 (a gnuplot escape), into buf. */
static void octal_slashes(const char *path, char *buf, size_t cap)
{
    size_t n = 0;
    for (; *path && n + 5 < cap; path++)
        if (*path == '/')
            n += (size_t)snprintf(buf + n, cap - n, "\\057");
        else
            buf[n++] = *path;
    buf[n] = '\0';
}

/* `pound record F --plot`: the record's name (its file name, in the chart's
 * title) spells a gnuplot command between double quotes; it never runs. */
static void test_plot_record_name(pd_test_ctx *ctx)
{
    plot_dir d;
    char rec[512], png[256], esc[128] = "";
    if (!have_tools(ctx) || dir_open(ctx, &d))
        return;
    octal_slashes(d.dir, esc, sizeof esc);
    snprintf(rec, sizeof rec, "%s/it's x\"; print system(\"touch %s\\057pwned\"); print \".txt",
             d.dir, esc);
    snprintf(png, sizeof png, "%s/r.png", d.dir);
    if (!CHECK(ctx, write_record(rec) == 0, "cannot write %s", rec)) {
        dir_close(&d);
        return;
    }
    const char *args[] = {"record", rec, "--units", "m/s2", "--plot", png, NULL};
    proc_out r;
    run_pound(ctx, &d, args, &r);
    check_plotted(ctx, &d, &r, png, 3);
    pd_test_proc_free(&r);
    dir_close(&d);
}

/* ---- what the scripts say (POUND_PLOT_SCRIPT=1 keeps F.gp and F.dat) ------ */

/* Run pound with args (NULL-terminated) keeping the script and data of its
 * --plot; 0 when it exited 0. */
static int run_keep(const pd_test_ctx *ctx, const char *const *args, proc_out *r)
{
    return run_pound_env(ctx, "POUND_PLOT_SCRIPT=1", args, r) == 0 && r->status == 0 ? 0 : -1;
}

/* The rows (x y) of block k of a gnuplot data file (blocks end with two
 * blank lines): their number, the first cap of them in x[], y[]. */
static long data_block(const char *dat, int k, double *x, double *y, long cap)
{
    long n = 0;
    int block = 0, blanks = 0;
    for (const char *l = dat; l && *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL) {
        if (*l == '\n') {
            if (++blanks == 2)
                block++;
            continue;
        }
        blanks = 0;
        if (block != k)
            continue;
        if (n < cap && x && y)
            sscanf(l, "%lf %lf", &x[n], &y[n]);
        n++;
    }
    return n;
}

/* The data block drawn as points (the impacts) on the plot line that
 * follows the k-th panel's `set title` line (k = -1: the first plot line),
 * -1 when that line has none. */
static int marks_block(const char *gp, int k)
{
    const char *l = gp;
    for (int i = 0; i <= k && l; i++)
        l = strstr(i ? l + 1 : l, "\nset title ");
    const char *plot = l ? strstr(l, "\nplot ") : NULL;
    const char *end = plot ? strchr(plot + 1, '\n') : NULL, *with = plot;
    int idx = -1;
    while (with && (with = strstr(with + 1, " with points")) && (!end || with < end)) {
        const char *i = with;
        while (i > plot && strncmp(i, " index ", 7))
            i--;
        idx = atoi(i + 7);
    }
    return idx;
}

/* The y of the dashed wall line on the plot line after position from. */
static double wall_line(const char *from)
{
    const char *w = strstr(from, " with lines lw 1.5 dt 2 lc rgb 'black'");
    const char *b = w;
    while (b && b > from && b[-1] != ' ')
        b--;
    return w ? strtod(b, NULL) : NAN;
}

/* Every method on the oscillator of the paper's Fig. 9 (5 impacts, 4 mm
 * gap): the wall is drawn at the gap, and each impact is marked once, on
 * the history where it touches the wall: as many marks as impacts, each
 * within one sample of the wall (the sample after an impact lies within dt
 * = 1.5e-4 s of it, at under 0.3 m/s: 5e-5 m; Moreau-Jean's and the
 * penalty elements' end-of-step positions are within their penetration). */
static void test_plot_oscillator_impacts(pd_test_ctx *ctx)
{
    static const char *const methods[] = {"moreau", "event", "penalty", "newmark"};
    char dir[] = "/tmp/pd_plmXXXXXX", png[64], gpf[64], datf[64];
    if (!have_tools(ctx) || !CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(png, sizeof png, "%s/o.png", dir);
    snprintf(gpf, sizeof gpf, "%s/o.gp", dir);
    snprintf(datf, sizeof datf, "%s/o.dat", dir);
    for (int m = 0; m < 4; m++) {
        const char *args[] = {"simulate", "--pulse", "sine", "--dir",    "normal",   "--Tp",
                              "0.3",      "--T0",    "3",    "--ap",     "4",        "--gap",
                              "0.004",    "--eps",   "0.6",  "--method", methods[m], "--json",
                              "--plot",   png,       NULL};
        proc_out r;
        int ok = run_keep(ctx, args, &r) == 0;
        char *gp = ok ? pd_test_slurp(gpf) : NULL, *dat = ok ? pd_test_slurp(datf) : NULL;
        if (CHECK(ctx, gp && dat, "%s: exit %d, %s", methods[m], r.status, r.err ? r.err : "")) {
            double impacts = pd_test_json_num(r.out, "impacts", 0), t[64], u[64];
            int k = marks_block(gp, -1);
            long n = k >= 0 ? data_block(dat, k, t, u, 64) : 0;
            CHECK(ctx, impacts == 5, "%s: %g impacts, expected 5", methods[m], impacts);
            CHECK(ctx, n == (long)impacts, "%s: %ld marks for %g impacts", methods[m], n, impacts);
            CHECK(ctx, wall_line(gp) == 0.004, "%s: wall drawn at %.17g, expected the gap 0.004",
                  methods[m], wall_line(gp));
            for (long i = 0; i < n && i < 64; i++)
                CHECK(ctx, fabs(u[i] - 0.004) <= 5e-5,
                      "%s: mark %ld at t = %g, u = %.6g m, off "
                      "the wall",
                      methods[m], i, t[i], u[i]);
        }
        free(gp);
        free(dat);
        pd_test_proc_free(&r);
        unlink(gpf);
        unlink(datf);
        unlink(png);
    }
    pd_test_rm_dir(dir);
}

/* The column of header name in a CSV header line (-1: none). */
static int csv_column(const char *header, const char *name)
{
    size_t len = strlen(name);
    int col = 0;
    for (const char *c = header; *c && *c != '\n'; col++) {
        if (!strncmp(c, name, len) && (c[len] == ',' || c[len] == '\n'))
            return col;
        while (*c && *c != ',' && *c != '\n')
            c++;
        if (*c == ',')
            c++;
    }
    return -1;
}

/* Field col of the CSV data row whose first field reads t (NAN: none);
 * the marks' times and the rows' are the same doubles printed %.17g. */
static double csv_at(const char *csv, double t, int col)
{
    for (const char *l = csv; l && *l; l = strchr(l, '\n') ? strchr(l, '\n') + 1 : NULL) {
        if (*l == '#' || *l == 't')
            continue;
        if (strtod(l, NULL) != t)
            continue;
        for (int c = 0; c < col && l; c++)
            l = strchr(l, ',') ? strchr(l, ',') + 1 : NULL;
        return l ? strtod(l, NULL) : NAN;
    }
    return NAN;
}

/* A scene of two buildings with contacts below their tops (a wall at the
 * 3-storey one's first floor, the 2-storey one against its floors 1 and 2),
 * the second named with every character enhanced text reads as markup:
 * a panel each; the name shown literally (escaped, never raw); the wall at
 * -gap in the first panel; every impact marked once, in the panel of each
 * structure it joins, at the storey of its contact: the marks of a storey
 * match the impacts of its contacts (Moreau-Jean samples every step, and a
 * contact begins at most one impact per step), each mark's value that
 * storey's displacement in the -o file at that instant. */
static void test_plot_scene_impacts(pd_test_ctx *ctx)
{
    char dir[] = "/tmp/pd_plsXXXXXX", scene[64], png[64], gpf[64], datf[64], csvf[64];
    if (!have_tools(ctx) || !CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(scene, sizeof scene, "%s/s.json", dir);
    snprintf(png, sizeof png, "%s/s.png", dir);
    snprintf(gpf, sizeof gpf, "%s/s.gp", dir);
    snprintf(datf, sizeof datf, "%s/s.dat", dir);
    snprintf(csvf, sizeof csvf, "%s/s.csv", dir);
    const char *json =
        "{\"excitation\": {\"pulse\": \"sine\", \"dir\": \"-x\", \"ap\": 4.0, \"Tp\": 0.8},\n"
        " \"structures\": [\n"
        "  {\"name\": \"low\", \"storeys\": 3, \"mass\": 3.0e5, \"T0\": 0.4, \"xi\": 0.05},\n"
        "  {\"name\": \"b_x^{y}@z&w\", \"storeys\": 2, \"mass\": 3.0e5, \"T0\": 1.0, \"xi\": "
        "0.05}],\n"
        " \"contacts\": [{\"a\": \"wall\", \"b\": \"low\", \"levels\": [1], \"gap\": 0.01, "
        "\"eps\": 0.5},\n"
        "  {\"a\": \"low\", \"b\": \"b_x^{y}@z&w\", \"levels\": [1, 2], \"gap\": 0.01, \"eps\": "
        "0.5}],\n"
        " \"tend\": 2.0}\n";
    if (!CHECK(ctx, write_text(scene, json) == 0, "cannot write %s", scene)) {
        pd_test_rm_dir(dir);
        return;
    }
    const char *args[] = {"simulate", "--scene", scene, "--method", "moreau", "--dt", "0.0005",
                          "--json",   "-o",      csvf,  "--plot",   png,      NULL};
    proc_out r;
    int ok = run_keep(ctx, args, &r) == 0;
    char *gp = ok ? pd_test_slurp(gpf) : NULL, *dat = ok ? pd_test_slurp(datf) : NULL;
    char *csv = ok ? pd_test_slurp(csvf) : NULL;
    if (CHECK(ctx, gp && dat && csv, "exit %d, %s", r.status, r.err ? r.err : "")) {
        CHECK(ctx, strstr(gp, "\"b\\\\_x\\\\^\\\\{y\\\\}\\\\\\100z\\\\&w\"") != NULL,
              "the name is not shown literally (escaped) in the script");
        CHECK(ctx, !strstr(gp, "b_x") && !strstr(gp, "{y}"), "the name reaches the script raw");
        /* impacts of contacts 0 (wall-low, low 1), 1 (low 1 - b 1), 2 (low 2 - b 2) */
        double imp[3];
        for (int c = 0; c < 3; c++)
            imp[c] = pd_test_json_num(r.out, "impacts", c + 1);
        CHECK(ctx, imp[0] + imp[1] + imp[2] >= 3, "too few impacts to test: %g %g %g", imp[0],
              imp[1], imp[2]);
        const char *header = strstr(csv, "\nt,");
        static const char *const name[2] = {"low", "b_x^{y}@z&w"};
        /* expected marks per (structure, storey): low 1 = c0 + c1, low 2 = c2, b 1 = c1, b 2 = c2 */
        double want[2][3] = {{0, imp[0] + imp[1], imp[2]}, {0, imp[1], imp[2]}};
        for (int s = 0; s < 2 && header; s++) {
            double t[512], y[512], got[3] = {0, 0, 0};
            int k = marks_block(gp, s), col[3] = {-1, -1, -1};
            long n = k >= 0 ? data_block(dat, k, t, y, 512) : 0;
            for (int L = 1; L <= 2; L++) {
                char cname[64];
                snprintf(cname, sizeof cname, "%s.x%d", name[s], L);
                col[L] = csv_column(header + 1, cname);
            }
            CHECK(ctx, n == (long)(want[s][1] + want[s][2]),
                  "%s: %ld marks, %g impacts at its "
                  "contacts",
                  name[s], n, want[s][1] + want[s][2]);
            for (long i = 0; i < n && i < 512; i++) {
                int at = 0;
                for (int L = 1; L <= 2; L++)
                    if (col[L] >= 0 && csv_at(csv, t[i], col[L]) == y[i]) {
                        got[L]++;
                        at = L;
                        break;
                    }
                CHECK(ctx, at > 0,
                      "%s: mark at t = %.17g, y = %.17g is no contact storey's "
                      "displacement",
                      name[s], t[i], y[i]);
            }
            for (int L = 1; L <= 2; L++)
                CHECK(ctx, got[L] == want[s][L], "%s storey %d: %g marks, %g impacts", name[s], L,
                      got[L], want[s][L]);
        }
        const char *low = strstr(gp, "\nset title \"low\"");
        CHECK(ctx, low && wall_line(low) == -0.01, "the wall of low drawn at %.17g, expected -0.01",
              low ? wall_line(low) : NAN);
    }
    free(gp);
    free(dat);
    free(csv);
    pd_test_proc_free(&r);
    unlink(scene);
    unlink(gpf);
    unlink(datf);
    unlink(csvf);
    unlink(png);
    pd_test_rm_dir(dir);
}

/* Ten spectra on one chart: the ten curves take line types 1..10, and the
 * palette's 36 line types are distinct (colour, dash) pairs over at least
 * twelve colours: no two curves look alike (gnuplot's default repeats
 * after eight). */
static void test_plot_palette(pd_test_ctx *ctx)
{
    char dir[] = "/tmp/pd_plpXXXXXX", png[64], gpf[64], datf[64], more[3][64];
    if (!have_tools(ctx) || !CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(png, sizeof png, "%s/p.png", dir);
    snprintf(gpf, sizeof gpf, "%s/p.gp", dir);
    snprintf(datf, sizeof datf, "%s/p.dat", dir);
    const char *args[] = {"spectrum",
                          "--pulse",
                          "sine",
                          "--dir",
                          "normal",
                          "--Pi3",
                          "0.01,0.02,0.05,0.1,0.2,0.3,0.5,1,2,5",
                          "--eps",
                          "0.5",
                          "--Pi2",
                          "0.5:2:3",
                          "--plot",
                          png,
                          NULL};
    proc_out r;
    int ok = run_keep(ctx, args, &r) == 0;
    char *gp = ok ? pd_test_slurp(gpf) : NULL;
    if (CHECK(ctx, gp != NULL, "exit %d, %s", r.status, r.err ? r.err : "")) {
        char colour[36][8] = {{0}}, seen[36][8];
        int dash[36] = {0}, ncol = 0;
        for (int k = 0; k < 36; k++) {
            char key[48];
            snprintf(key, sizeof key, "set linetype %d lc rgb '", k + 1);
            const char *l = strstr(gp, key);
            if (!CHECK(ctx, l != NULL, "no line type %d", k + 1))
                break;
            sscanf(l + strlen(key), "%7[#0-9A-Fa-f]' lw %*s dt %d", colour[k], &dash[k]);
            for (int j = 0; j < k; j++)
                CHECK(ctx, strcmp(colour[j], colour[k]) || dash[j] != dash[k],
                      "line types %d and %d alike (%s, dt %d)", j + 1, k + 1, colour[k], dash[k]);
            int fresh = 1;
            for (int j = 0; j < ncol; j++)
                fresh &= strcmp(seen[j], colour[k]) != 0;
            if (fresh)
                memcpy(seen[ncol++], colour[k], 8);
        }
        CHECK(ctx, ncol >= 12, "%d colours in the palette", ncol);
        const char *plot = strstr(gp, "\nplot "), *end = plot ? strchr(plot + 1, '\n') : NULL;
        int curves = 0;
        for (const char *i = plot; i && (i = strstr(i + 1, " index ")) && (!end || i < end);)
            curves++;
        CHECK(ctx, curves == 10 && plot && !strstr(plot, " lc "),
              "%d curves drawn, expected 10 taking the palette's line types", curves);
    }
    free(gp);
    pd_test_proc_free(&r);
    snprintf(more[0], sizeof more[0], "%s/p-gamma.png", dir);
    snprintf(more[1], sizeof more[1], "%s/p-gamma.gp", dir);
    snprintf(more[2], sizeof more[2], "%s/p-gamma.dat", dir);
    for (int k = 0; k < 3; k++)
        unlink(more[k]);
    unlink(gpf);
    unlink(datf);
    unlink(png);
    pd_test_rm_dir(dir);
}

void suite_plots(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_plot_name_injection);
    PD_RUN(ctx, test_plot_odd_name);
    PD_RUN(ctx, test_plot_across_file_systems);
    PD_RUN(ctx, test_plot_missing_dir);
    PD_RUN(ctx, test_plot_scene_names);
    PD_RUN(ctx, test_plot_record_name);
    PD_RUN(ctx, test_plot_oscillator_impacts);
    PD_RUN(ctx, test_plot_scene_impacts);
    PD_RUN(ctx, test_plot_palette);
}
