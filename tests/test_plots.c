/* test_plots.c — --plot never hands gnuplot a file name or a text as script:
 * output names with quotes, backslashes and bytes beyond ASCII; structure,
 * scene and record names built to inject commands; a failed plot writes
 * nothing to standard output and leaves no temporary file behind. */
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

/* Run pound with args (NULL-terminated) and TMPDIR set to the tmp/ folder. */
static int run_pound(const pd_test_ctx *ctx, const plot_dir *d, const char *const *args,
                     proc_out *r)
{
    const char *argv[32];
    int n = 0;
    argv[n++] = ctx->pound;
    for (; args[n - 1] && n < 31; n++)
        argv[n] = args[n - 1];
    argv[n] = NULL;
    return pd_test_spawn(argv, d->env, r);
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
static void check_plotted(pd_test_ctx *ctx, const plot_dir *d, const proc_out *r,
                          const char *png, int entries)
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
    CHECK(ctx, pd_test_dir_entries(shm) == 0, "%d temporaries left in %s",
          pd_test_dir_entries(shm), shm);
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
    snprintf(json, sizeof json, "%s",
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
                 " \"structures\": [{\"name\": \"%s\", \"T0\": 0.4}]}\n", refused[k]);
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
        fprintf(f, "%.2f %.6g\n", t, t >= 1.0 && t <= 2.0 ? 3.0 * sin(6.283185307179586 * (t - 1.0))
                                                           : 0.0);
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

void suite_plots(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_plot_name_injection);
    PD_RUN(ctx, test_plot_odd_name);
    PD_RUN(ctx, test_plot_across_file_systems);
    PD_RUN(ctx, test_plot_missing_dir);
    PD_RUN(ctx, test_plot_scene_names);
    PD_RUN(ctx, test_plot_record_name);
}
