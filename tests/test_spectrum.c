/* test_spectrum.c — `pound spectrum`: agreement with `pound simulate`,
 * bit-identical output across thread counts, MPI ranks and resumed runs,
 * bad input, HDF5/CSV read back, the Pi2 grid, the dimensional view. */
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_problems.h"
#include "pd_cpu.h"
#include "pd_test.h"

/* |a - b| <= tol max(|a|, |b|), NaN equal to NaN. */
static int rel_close(double a, double b, double tol)
{
    if (isnan(a) || isnan(b))
        return isnan(a) && isnan(b);
    return fabs(a - b) <= tol * fmax(fabs(a), fabs(b));
}

/* ---- agreement with simulate ------------------------------------------- */

/* Every point of a small sweep equals `pound simulate --json` on the same
 * case (Pi1, gamma, chi, umax_free, impacts), for Moreau-Jean and the
 * event-driven reference; SPEC keys present; quiet stderr. */
static void test_spectrum_matches_simulate(pd_test_ctx *ctx)
{
    static const char *const methods[] = {"moreau", "event"};
    static const char *const keys[] = {"pulse", "dir",       "Pi2",   "Pi3", "eps",     "xi",
                                       "Pi1",   "umax_free", "gamma", "chi", "impacts", "method"};
    if (!pd_test_have_pound(ctx))
        return;
    for (int m = 0; m < 2; m++) {
        const char *args[] = {"spectrum", "--pulse",  "sine,cosine", "--dir",  "normal,reverse",
                              "--Pi2",    "0.2:3:3",  "--Pi3",       "0.05",   "--eps",
                              "0.6",      "--method", methods[m],    "--json", NULL};
        proc_out sp;
        pd_test_pound(ctx, args, &sp);
        CHECK(ctx, sp.status == 0, "%s: exit %d: %s", methods[m], sp.status, sp.err);
        CHECK(ctx, sp.err[0] == '\0', "%s: stderr not quiet: %s", methods[m], sp.err);
        for (size_t k = 0; k < sizeof keys / sizeof keys[0]; k++) {
            char pat[32];
            snprintf(pat, sizeof pat, "\"%s\":", keys[k]);
            CHECK(ctx, strstr(sp.out, pat) != NULL, "point key %s missing", keys[k]);
        }
        CHECK(ctx,
              isfinite(pd_test_json_num(sp.out, "cpu_s", 12)) &&
                  isfinite(pd_test_json_num(sp.out, "wall_s", 0)),
              "totals cpu_s, wall_s missing");
        for (int p = 0; p < 12; p++) {
            char pulse[16], dir[16], pi2[40];
            pd_test_json_str(sp.out, "pulse", p, pulse, sizeof pulse);
            pd_test_json_str(sp.out, "dir", p, dir, sizeof dir);
            snprintf(pi2, sizeof pi2, "%.17g", pd_test_json_num(sp.out, "Pi2", p));
            const char *sargs[] = {"simulate", "--pulse",  pulse,      "--dir",  dir,
                                   "--Pi2",    pi2,        "--Pi3",    "0.05",   "--eps",
                                   "0.6",      "--method", methods[m], "--json", NULL};
            proc_out sim;
            pd_test_pound(ctx, sargs, &sim);
            static const char *const cmp[] = {"Pi1", "gamma", "chi", "umax_free", "impacts"};
            for (int c = 0; c < 5; c++) {
                double a = pd_test_json_num(sp.out, cmp[c], p),
                       b = pd_test_json_num(sim.out, cmp[c], 0);
                CHECK(ctx, rel_close(a, b, 1e-12) && isfinite(a),
                      "%s %s %s Pi2 = %s: %s spectrum %.17g vs simulate %.17g", methods[m], pulse,
                      dir, pi2, cmp[c], a, b);
            }
            pd_test_proc_free(&sim);
        }
        pd_test_proc_free(&sp);
    }
}

/* ---- bit identity -------------------------------------------------------- */

/* The sweep used for the identity checks: 4 curves x 12 Pi2. */
#define SWEEP                                                                                      \
    "--pulse", "sine,cosine", "--dir", "normal,reverse", "--Pi2", "0.08:4:12", "--Pi3", "0.02",    \
        "--eps", "0.7"

/* HDF5 and CSV written on 1 and on 2 threads are byte-identical. */
static void test_spectrum_threads_bit_identical(pd_test_ctx *ctx)
{
    static const char *const ext[] = {"h5", "csv"};
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_spec_thrXXXXXX", f1[512], f2[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    for (int e = 0; e < 2; e++) {
        proc_out r1, r2;
        snprintf(f1, sizeof f1, "%s/t1.%s", dir, ext[e]);
        snprintf(f2, sizeof f2, "%s/t2.%s", dir, ext[e]);
        const char *a1[] = {"spectrum", SWEEP, "--threads", "1", "-o", f1, NULL};
        const char *a2[] = {"spectrum", SWEEP, "--threads", "2", "-o", f2, NULL};
        pd_test_pound(ctx, a1, &r1);
        pd_test_pound(ctx, a2, &r2);
        CHECK(ctx, r1.status == 0 && r2.status == 0, "exit %d / %d: %s %s", r1.status, r2.status,
              r1.err, r2.err);
        CHECK(ctx, pd_test_same_file(f1, f2), "%s: 1 and 2 threads differ", ext[e]);
        pd_test_proc_free(&r1);
        pd_test_proc_free(&r2);
    }
    pd_test_rm_dir(dir);
}

/* A sweep killed mid-way (the --stop-after hook, twice) and resumed gives
 * the uninterrupted file byte for byte; a torn journal line is dropped; a
 * fresh run refuses to overwrite the journal; a resume with other flags is
 * refused naming the flag; the journal is gone at the end. */
static void test_spectrum_resume(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_spec_resXXXXXX", full[512], part[512], journal[600];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(full, sizeof full, "%s/full.h5", dir);
    snprintf(part, sizeof part, "%s/part.h5", dir);
    snprintf(journal, sizeof journal, "%s.partial", part);
    proc_out r;
    const char *a_full[] = {"spectrum", SWEEP, "-o", full, NULL};
    pd_test_pound(ctx, a_full, &r);
    CHECK(ctx, r.status == 0, "uninterrupted: exit %d: %s", r.status, r.err);
    pd_test_proc_free(&r);
    const char *a_stop[] = {"spectrum", SWEEP,          "-o", part, "--threads",
                            "2",        "--stop-after", "20", NULL};
    pd_test_pound(ctx, a_stop, &r);
    CHECK(ctx, r.status == 130, "killed run: exit %d, expected 130", r.status);
    CHECK(ctx, access(part, F_OK) != 0 && access(journal, F_OK) == 0,
          "after the kill: no final file, a journal");
    pd_test_proc_free(&r);
    FILE *j = fopen(journal, "a");
    if (j) { /* a torn last line, as a kill during a write would leave */
        fputs("T 3 0x1.8p-3 0x1", j);
        fclose(j);
    }
    const char *a_fresh[] = {"spectrum", SWEEP, "-o", part, NULL};
    pd_test_pound(ctx, a_fresh, &r);
    CHECK(ctx, r.status == 2 && strstr(r.err, "--resume"),
          "a fresh run over a journal: exit %d (%s)", r.status, r.err);
    pd_test_proc_free(&r);
    const char *a_other[] = {"spectrum", SWEEP, "--xi", "0.02", "-o", part, "--resume", NULL};
    pd_test_pound(ctx, a_other, &r);
    CHECK(ctx, r.status == 2 && strstr(r.err, "--xi"), "resume with another xi: exit %d (%s)",
          r.status, r.err);
    pd_test_proc_free(&r);
    const char *a_stop2[] = {"spectrum", SWEEP, "-o", part, "--resume", "--stop-after", "15", NULL};
    pd_test_pound(ctx, a_stop2, &r);
    CHECK(ctx, r.status == 130, "second kill: exit %d", r.status);
    pd_test_proc_free(&r);
    const char *a_res[] = {"spectrum", SWEEP, "-o", part, "--resume", "--json", NULL};
    pd_test_pound(ctx, a_res, &r);
    CHECK(ctx, r.status == 0, "resume: exit %d: %s", r.status, r.err);
    CHECK(ctx, pd_test_json_num(r.out, "resumed", 0) == 35, "resumed %g runs, expected 35",
          pd_test_json_num(r.out, "resumed", 0));
    CHECK(ctx, pd_test_same_file(full, part), "resumed file differs from the uninterrupted one");
    CHECK(ctx, access(journal, F_OK) != 0, "journal left behind");
    pd_test_proc_free(&r);
    pd_test_rm_dir(dir);
}

/* ---- bad input ----------------------------------------------------------- */

/* Every bad input: exit 2, one stderr line naming the flag, nothing on
 * stdout, no file (neither -o, nor the journal, nor a chart). */
static void test_spectrum_bad_input(pd_test_ctx *ctx)
{
    static const struct {
        const char *a[5];
        const char *named;
        int no_out, no_pi2;
    } cases[] = {{{"--T0", "2"}, "--T0", 0, 0},
                 {{"--Pi2", "1"}, "--Pi2", 0, 0},
                 {{"--Pi2", "2:1:5"}, "--Pi2", 0, 0},
                 {{"--Pi2", "0:1:5"}, "--Pi2", 0, 0},
                 {{"--Pi2", "0.5:2:x"}, "--Pi2", 0, 0},
                 {{"--Pi2", "0.5:2"}, "--Pi2", 0, 0},
                 {{"--eps", "0.5,1.5"}, "--eps", 0, 0},
                 {{"--eps", "0.5,"}, "--eps", 0, 0},
                 {{"--xi", "0.05,1"}, "--xi", 0, 0},
                 {{"--Pi3", "0.1,-1"}, "--Pi3", 0, 0},
                 {{"--gap", "-0.01"}, "--gap", 0, 0},
                 {{"--pulse", "sine,triangle"}, "--pulse", 0, 0},
                 {{"--dir", "normal,up"}, "--dir", 0, 0},
                 {{"--ap", "1,0"}, "--ap", 0, 0},
                 {{"--Tp", "-1"}, "--Tp", 0, 0},
                 {{"--threads", "0"}, "--threads", 0, 0},
                 {{"--method", "magic"}, "--method", 0, 0},
                 {{"--dt", "0"}, "--dt", 0, 0},
                 {{"--dt-per-Tp", "-5"}, "--dt-per-Tp", 0, 0},
                 {{"--theta", "0.2"}, "--theta", 0, 0},
                 {{"--no-wall"}, "--no-wall", 0, 0},
                 {{"--bogus", "1"}, "bogus", 0, 0},
                 {{"--plot", "x.jpg"}, "--plot", 0, 0},
                 {{"-o", "x.txt"}, "x.txt", 0, 0},
                 {{"--Pi3", "0.1", "--gap", "0.01"}, "--gap", 0, 0},
                 {{"--dt", "0.001", "--dt-per-Tp", "100"}, "--dt-per-Tp", 0, 0},
                 {{"--resume"}, "--resume", 1, 0},
                 {{"--eps", "0.5"}, "--Pi2", 0, 1}};
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_spec_badXXXXXX", out[512], png[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(out, sizeof out, "%s/s.h5", dir);
    snprintf(png, sizeof png, "%s/s.png", dir);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *args[20];
        int n = 0;
        args[n++] = "spectrum";
        if (!cases[k].no_pi2) {
            args[n++] = "--Pi2";
            args[n++] = "0.5:2:3";
        }
        if (!cases[k].no_out) {
            args[n++] = "-o";
            args[n++] = out;
            args[n++] = "--plot";
            args[n++] = png;
        }
        for (int i = 0; i < 5 && cases[k].a[i]; i++)
            args[n++] = cases[k].a[i];
        args[n] = NULL;
        proc_out r;
        pd_test_pound(ctx, args, &r);
        char *nl = strchr(r.err, '\n');
        CHECK(ctx, r.status == 2, "%s %s: exit %d, expected 2 (%s)", cases[k].a[0],
              cases[k].a[1] ? cases[k].a[1] : "", r.status, r.err);
        CHECK(ctx, strstr(r.err, cases[k].named) != NULL, "%s: message does not name %s: %s",
              cases[k].a[0], cases[k].named, r.err);
        CHECK(ctx, nl && nl[1] == '\0', "%s: stderr must be one line: %s", cases[k].a[0], r.err);
        CHECK(ctx, r.out[0] == '\0', "%s: nothing on stdout: %s", cases[k].a[0], r.out);
        CHECK(ctx, pd_test_dir_entries(dir) == 0, "%s: a file was left behind", cases[k].a[0]);
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* The plain build (the one under test) started as one of several copies,
 * as mpirun would start it, refuses instead of writing the sweep twice. */
static void test_spectrum_refuses_copies_without_mpi(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_spec_cpyXXXXXX", out[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(out, sizeof out, "%s/s.h5", dir);
    const char *argv[] = {ctx->pound, "spectrum", "--Pi2", "0.5:2:3", "-o", out, NULL};
    proc_out r;
    pd_test_spawn(argv, "OMPI_COMM_WORLD_SIZE=2", &r);
    CHECK(ctx, r.status == 2 && strstr(r.err, "MPI=1"), "exit %d: %s", r.status, r.err);
    CHECK(ctx, pd_test_dir_entries(dir) == 0, "a file was written");
    pd_test_proc_free(&r);
    pd_test_rm_dir(dir);
}

/* ---- files read back ----------------------------------------------------- */

/* A string attribute into buf ("" when missing). */
static void h5_str_attr(hid_t obj, const char *name, char *buf, size_t cap)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), t = a >= 0 ? H5Aget_type(a) : -1;
    buf[0] = '\0';
    if (t >= 0 && H5Tget_size(t) <= cap)
        H5Aread(a, t, buf);
    if (t >= 0)
        H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
}

/* Dataset name of group g (n values) into x: 0 or -1. */
static int h5_read(hid_t g, const char *name, double *x, int n)
{
    hid_t ds = H5Dopen2(g, name, H5P_DEFAULT), sp = ds >= 0 ? H5Dget_space(ds) : -1;
    hsize_t dims[1] = {0};
    int rc = -1;
    if (sp >= 0 && H5Sget_simple_extent_dims(sp, dims, NULL) == 1 && dims[0] == (hsize_t)n &&
        H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x) >= 0)
        rc = 0;
    if (sp >= 0)
        H5Sclose(sp);
    if (ds >= 0)
        H5Dclose(ds);
    return rc;
}

/* One curve group against the JSON points p0 .. p0 + 4. */
static void check_group(pd_test_ctx *ctx, hid_t f, int c, const char *json)
{
    static const char *const cols[] = {"Pi2", "Pi1", "gamma", "chi", "impacts", "umax_free"};
    char name[32], pulse[16], jpulse[16];
    double x[5];
    snprintf(name, sizeof name, "curve_%04d", c);
    hid_t g = H5Gopen2(f, name, H5P_DEFAULT);
    if (!CHECK(ctx, g >= 0, "group %s missing", name))
        return;
    h5_str_attr(g, "pulse", pulse, sizeof pulse);
    pd_test_json_str(json, "pulse", 5 * c, jpulse, sizeof jpulse);
    CHECK(ctx, !strcmp(pulse, jpulse), "%s: pulse '%s' vs '%s'", name, pulse, jpulse);
    CHECK(ctx,
          pd_test_h5_num(g, "Pi3") == pd_test_json_num(json, "Pi3", 5 * c) &&
              pd_test_h5_num(g, "eps") == 0.4 && pd_test_h5_num(g, "xi") == 0.05,
          "%s: attributes Pi3 %g eps %g xi %g", name, pd_test_h5_num(g, "Pi3"),
          pd_test_h5_num(g, "eps"), pd_test_h5_num(g, "xi"));
    for (int k = 0; k < 6; k++) {
        if (!CHECK(ctx, h5_read(g, cols[k], x, 5) == 0, "%s/%s unreadable", name, cols[k]))
            continue;
        for (int j = 0; j < 5; j++)
            CHECK(ctx, x[j] == pd_test_json_num(json, cols[k], 5 * c + j),
                  "%s/%s[%d] = %.17g vs %.17g", name, cols[k], j, x[j],
                  pd_test_json_num(json, cols[k], 5 * c + j));
    }
    H5Gclose(g);
}

/* The CSV: a header row with the columns, one row per point, values equal
 * to the JSON ones. */
static void check_csv(pd_test_ctx *ctx, const char *path, const char *json)
{
    char *text = pd_test_slurp(path), *line = text, *save = NULL;
    int rows = 0, col_pi1 = -1, col_gamma = -1;
    for (line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        if (line[0] == '#')
            continue;
        if (col_pi1 < 0) { /* the header row */
            int c = 0;
            for (char *s2 = NULL, *tok = strtok_r(line, ",", &s2); tok;
                 tok = strtok_r(NULL, ",", &s2), c++) {
                col_pi1 = !strcmp(tok, "Pi1") ? c : col_pi1;
                col_gamma = !strcmp(tok, "gamma") ? c : col_gamma;
            }
            continue;
        }
        int c = 0;
        double pi1 = NAN, gamma = NAN;
        for (char *s2 = NULL, *tok = strtok_r(line, ",", &s2); tok;
             tok = strtok_r(NULL, ",", &s2), c++) {
            pi1 = c == col_pi1 ? strtod(tok, NULL) : pi1;
            gamma = c == col_gamma ? strtod(tok, NULL) : gamma;
        }
        CHECK(ctx,
              pi1 == pd_test_json_num(json, "Pi1", rows) &&
                  gamma == pd_test_json_num(json, "gamma", rows),
              "CSV row %d: Pi1 %.17g gamma %.17g differ from the JSON", rows, pi1, gamma);
        rows++;
    }
    CHECK(ctx, col_pi1 >= 0 && col_gamma >= 0, "CSV header lacks Pi1/gamma");
    CHECK(ctx, rows == 20, "CSV has %d rows, expected 20", rows);
    free(text);
}

/* -o run.h5: one group per curve with its parameters as attributes and the
 * datasets Pi2, Pi1, gamma, chi, impacts, umax_free; -o run.csv: one row
 * per point; both equal the JSON to the bit. */
static void test_spectrum_hdf5_csv_read_back(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_spec_rbXXXXXX", h5[512], csv[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(h5, sizeof h5, "%s/s.h5", dir);
    snprintf(csv, sizeof csv, "%s/s.csv", dir);
    const char *a1[] = {"spectrum", "--pulse", "sine,cosine", "--Pi3", "0.01,0.1", "--eps", "0.4",
                        "--Pi2",    "0.3:3:5", "--json",      "-o",    h5,         NULL};
    const char *a2[] = {"spectrum", "--pulse", "sine,cosine", "--Pi3", "0.01,0.1", "--eps",
                        "0.4",      "--Pi2",   "0.3:3:5",     "-o",    csv,        NULL};
    proc_out r, r2;
    pd_test_pound(ctx, a1, &r);
    pd_test_pound(ctx, a2, &r2);
    CHECK(ctx, r.status == 0 && r2.status == 0, "exit %d / %d: %s", r.status, r2.status, r.err);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (CHECK(ctx, f >= 0, "cannot open %s", h5)) {
        CHECK(ctx, pd_test_h5_num(f, "curves") == 4 && pd_test_h5_num(f, "points") == 20,
              "root attributes curves %g points %g", pd_test_h5_num(f, "curves"),
              pd_test_h5_num(f, "points"));
        for (int c = 0; c < 4; c++)
            check_group(ctx, f, c, r.out);
        H5Fclose(f);
    }
    check_csv(ctx, csv, r.out);
    pd_test_proc_free(&r);
    pd_test_proc_free(&r2);
    pd_test_rm_dir(dir);
}

/* ---- the grid, the twins, the dimensional view --------------------------- */

/* --linear gives equal steps, the default equal ratios; end points exact. */
static void test_spectrum_linear_vs_log(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    for (int lin = 0; lin < 2; lin++) {
        const char *args[] = {"spectrum", "--Pi2", "0.5:2.5:5", "--json", lin ? "--linear" : NULL,
                              NULL};
        proc_out r;
        pd_test_pound(ctx, args, &r);
        CHECK(ctx, r.status == 0, "exit %d: %s", r.status, r.err);
        for (int j = 0; j < 5; j++) {
            double x = pd_test_json_num(r.out, "Pi2", j);
            double want = lin ? 0.5 + 0.5 * j : 0.5 * pow(5.0, j / 4.0);
            CHECK(ctx, rel_close(x, want, 1e-15), "%s Pi2[%d] = %.17g, expected %.17g",
                  lin ? "linear" : "log", j, x, want);
        }
        CHECK(ctx,
              pd_test_json_num(r.out, "Pi2", 0) == 0.5 && pd_test_json_num(r.out, "Pi2", 4) == 2.5,
              "end points not exact");
        pd_test_proc_free(&r);
    }
}

/* The no-wall twin is run once per (pulse, dir, Pi2, xi) and shared by the
 * gaps and restitutions: 4 twins for 16 points, equal umax_free. */
static void test_spectrum_twins_shared(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    const char *args[] = {"spectrum", "--Pi3",   "0.01,0.1", "--eps", "0.2,0.9",
                          "--Pi2",    "0.3:3:4", "--json",   NULL};
    proc_out r;
    pd_test_pound(ctx, args, &r);
    CHECK(ctx, r.status == 0, "exit %d: %s", r.status, r.err);
    CHECK(ctx, pd_test_json_num(r.out, "runs", 0) == 20 && pd_test_json_num(r.out, "twins", 0) == 4,
          "runs %g twins %g, expected 20 and 4", pd_test_json_num(r.out, "runs", 0),
          pd_test_json_num(r.out, "twins", 0));
    for (int c = 1; c < 4; c++)
        for (int j = 0; j < 4; j++)
            CHECK(ctx,
                  pd_test_json_num(r.out, "umax_free", 4 * c + j) ==
                      pd_test_json_num(r.out, "umax_free", j),
                  "curve %d Pi2 #%d: umax_free differs", c, j);
    pd_test_proc_free(&r);
}

/* The dimensional view: amplitudes 1, 2.5, 7 m/s^2 at the same Pi3 give
 * the same Pi1 curve (1e-12), umax in proportion to ap, T0 = Tp / Pi2;
 * with --gap the Pi3 of each curve is gap wp^2 / ap. */
static void test_spectrum_dimensional_self_similar(pd_test_ctx *ctx)
{
    static const double ap[] = {1.0, 2.5, 7.0};
    if (!pd_test_have_pound(ctx))
        return;
    const char *args[] = {"spectrum", "--ap",  "1,2.5,7", "--Tp",   "0.4",
                          "--Pi3",    "0.05",  "--pulse", "cosine", "--dir",
                          "reverse",  "--Pi2", "0.3:3:6", "--json", NULL};
    proc_out r;
    pd_test_pound(ctx, args, &r);
    CHECK(ctx, r.status == 0, "exit %d: %s", r.status, r.err);
    for (int c = 1; c < 3; c++)
        for (int j = 0; j < 6; j++) {
            int p = 6 * c + j;
            CHECK(ctx,
                  rel_close(pd_test_json_num(r.out, "Pi1", p), pd_test_json_num(r.out, "Pi1", j),
                            1e-12),
                  "ap %g Pi2 #%d: Pi1 %.17g vs %.17g", ap[c], j, pd_test_json_num(r.out, "Pi1", p),
                  pd_test_json_num(r.out, "Pi1", j));
            CHECK(ctx,
                  rel_close(pd_test_json_num(r.out, "umax", p) / ap[c],
                            pd_test_json_num(r.out, "umax", j), 1e-12),
                  "ap %g: umax not proportional to ap", ap[c]);
            CHECK(ctx,
                  rel_close(pd_test_json_num(r.out, "T0", p),
                            0.4 / pd_test_json_num(r.out, "Pi2", p), 1e-15),
                  "T0 != Tp / Pi2");
        }
    pd_test_proc_free(&r);
    const char *gargs[] = {"spectrum", "--ap",  "1,2",     "--Tp",   "0.4", "--gap",
                           "0.002",    "--Pi2", "0.5:1:2", "--json", NULL};
    pd_test_pound(ctx, gargs, &r);
    CHECK(ctx, r.status == 0, "--gap: exit %d: %s", r.status, r.err);
    double wp = 6.283185307179586 / 0.4;
    for (int c = 0; c < 2; c++)
        CHECK(ctx,
              rel_close(pd_test_json_num(r.out, "Pi3", 2 * c), 0.002 * wp * wp / (c + 1.0), 1e-12),
              "--gap: curve %d Pi3 %.17g", c, pd_test_json_num(r.out, "Pi3", 2 * c));
    pd_test_proc_free(&r);
}

/* --plot F.png draws F.png, F-gamma.png and, with --ap, F-dim.png. */
static void test_spectrum_plot(pd_test_ctx *ctx)
{
    static const char *const suffix[] = {".png", "-gamma.png", "-dim.png"};
    const char *gp[] = {"gnuplot", "--version", NULL};
    proc_out g;
    if (!pd_test_have_pound(ctx))
        return;
    if (pd_test_spawn(gp, NULL, &g) != 0) {
        pd_test_proc_free(&g);
        pd_test_skip(ctx, "gnuplot not installed");
        return;
    }
    pd_test_proc_free(&g);
    char dir[] = "/tmp/pd_spec_pltXXXXXX", png[512], path[600];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(png, sizeof png, "%s/s.png", dir);
    const char *args[] = {"spectrum", "--ap",    "1,2",    "--Pi3", "0.01,0.1",
                          "--Pi2",    "0.2:5:8", "--plot", png,     NULL};
    proc_out r;
    pd_test_pound(ctx, args, &r);
    CHECK(ctx, r.status == 0, "exit %d: %s", r.status, r.err);
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/s%s", dir, suffix[k]);
        char *bytes = pd_test_slurp(path);
        CHECK(ctx, bytes && !strncmp(bytes + 1, "PNG", 3), "%s missing or not a PNG", path);
        free(bytes);
    }
    CHECK(ctx, pd_test_dir_entries(dir) == 3, "%d files in the folder, expected the 3 charts",
          pd_test_dir_entries(dir));
    pd_test_proc_free(&r);
    pd_test_rm_dir(dir);
}

/* ---- MPI ------------------------------------------------------------------ */

/* mpirun -np 2 of the MPI build (POUND_MPI, default build-mpi/pound) writes
 * the file of the serial run byte for byte, with 1 and 2 threads per rank. */
static void test_spectrum_mpi_matches_serial(pd_test_ctx *ctx)
{
    const char *mpi = getenv("POUND_MPI") ? getenv("POUND_MPI") : "build-mpi/pound";
    const char *probe[] = {"mpirun", "--version", NULL};
    proc_out r;
    if (!pd_test_have_pound(ctx))
        return;
    if (access(mpi, X_OK) != 0) {
        pd_test_skip(ctx, "no MPI build (make MPI=1)");
        return;
    }
    if (pd_test_spawn(probe, NULL, &r) != 0) {
        pd_test_proc_free(&r);
        pd_test_skip(ctx, "no mpirun");
        return;
    }
    pd_test_proc_free(&r);
    char dir[] = "/tmp/pd_spec_mpiXXXXXX", ser[512], par[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(ser, sizeof ser, "%s/serial.h5", dir);
    snprintf(par, sizeof par, "%s/mpi.h5", dir);
    const char *a_ser[] = {"spectrum", SWEEP, "--threads", "1", "-o", ser, NULL};
    pd_test_pound(ctx, a_ser, &r);
    CHECK(ctx, r.status == 0, "serial: exit %d: %s", r.status, r.err);
    pd_test_proc_free(&r);
    for (int th = 1; th <= 2; th++) {
        const char *a_mpi[] = {"mpirun",
                               "-np",
                               "2",
                               "--allow-run-as-root",
                               "--oversubscribe",
                               mpi,
                               "spectrum",
                               SWEEP,
                               "--threads",
                               th == 1 ? "1" : "2",
                               "-o",
                               par,
                               "--json",
                               NULL};
        unlink(par);
        pd_test_spawn(a_mpi, NULL, &r);
        CHECK(ctx, r.status == 0, "mpirun: exit %d: %s", r.status, r.err);
        CHECK(ctx, pd_test_json_num(r.out, "ranks", 0) == 2, "ranks %g in the JSON, expected 2",
              pd_test_json_num(r.out, "ranks", 0));
        CHECK(ctx, pd_test_same_file(ser, par),
              "MPI (2 ranks x %d threads) file differs from serial", th);
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* ---- the library's sweep with a callback (pd_spec_sweep) ----------------- */

/* What the callback saw. */
typedef struct sweep_seen {
    int calls, stop_at; /* stop_at > 0: ask to stop on that call */
    pd_spec_coords co[64];
    pd_spec_row row[64];
} sweep_seen;

static int sweep_point(const pd_spec_coords *co, const pd_spec_row *row, void *ctx)
{
    sweep_seen *seen = ctx;
    if (seen->calls < 64) {
        seen->co[seen->calls] = *co;
        seen->row[seen->calls] = *row;
    }
    return ++seen->calls == seen->stop_at;
}

/* Equal, NaN equal to NaN. */
static int same(double a, double b)
{
    return a == b || (isnan(a) && isnan(b));
}

/* 2 pulses x 2 eps x 4 Pi2 (8 twins, 16 points), event-driven and
 * Moreau-Jean: the callback gets every point once, in order, with the
 * coordinates of pd_spec_coords_of and the numbers of pd_spec_run_task +
 * pd_spec_rows, bit for bit; a nonzero return stops it (PD_ESTOPPED) on
 * that point; a bad sweep is refused before any run. */
static void test_spectrum_sweep_callback(pd_test_ctx *ctx)
{
    for (int m = 0; m < 2; m++) {
        pd_spectrum s;
        pd_spec_init(&s);
        s.opts.method = m ? PD_METHOD_MOREAU : PD_METHOD_EVENT;
        s.dt_per_Tp = m ? 500 : 0;
        s.pi2_min = 0.3, s.pi2_max = 3, s.npi2 = 4;
        s.npulse = 2, s.pulse[1] = PD_PULSE_COSINE;
        s.neps = 2, s.eps[0] = 0.5, s.eps[1] = 0.8;
        long ntw = pd_spec_twins(&s), np = pd_spec_points(&s), nt = pd_spec_tasks(&s);
        pd_spec_result res[32];
        pd_spec_row rows[16];
        pd_err err;
        if (!CHECK(ctx, ntw == 8 && np == 16, "%ld twins, %ld points", ntw, np))
            return;
        for (long t = 0; t < nt; t++)
            pd_spec_run_task(&s, t, &res[t], &err);
        pd_spec_rows(&s, res, rows);
        sweep_seen seen = {0};
        int rc = pd_spec_sweep(&s, sweep_point, &seen, &err);
        CHECK(ctx, rc == PD_OK && seen.calls == np, "method %d: rc %d (%s), %d calls", m, rc,
              err.msg, seen.calls);
        for (int p = 0; p < seen.calls && p < np; p++) {
            pd_spec_coords co;
            const pd_spec_row *a = &seen.row[p], *b = &rows[p];
            pd_spec_coords_of(&s, ntw + p, &co);
            CHECK(ctx, !memcmp(&co, &seen.co[p], sizeof co), "point %d: coordinates differ", p);
            CHECK(ctx,
                  a->c.Pi2 == b->c.Pi2 && a->c.Pi3 == b->c.Pi3 && a->c.eps == b->c.eps &&
                      a->c.pulse == b->c.pulse && a->c.dir == b->c.dir && a->curve == b->curve &&
                      a->c.Pi2 == pd_spec_pi2(&s, co.j),
                  "point %d: case differs", p);
            CHECK(ctx, a->umax == res[ntw + p].umax && a->umax > 0.0,
                  "point %d: umax %.17g vs pd_spec_run_task %.17g", p, a->umax, res[ntw + p].umax);
            CHECK(ctx, a->umax_free == res[pd_spec_twin_of(&s, ntw + p)].umax,
                  "point %d: umax_free %.17g vs the twin's %.17g", p, a->umax_free,
                  res[pd_spec_twin_of(&s, ntw + p)].umax);
            CHECK(ctx,
                  same(a->Pi1, b->Pi1) && same(a->gamma, b->gamma) && same(a->chi, b->chi) &&
                      a->impacts == b->impacts && a->steps == b->steps && isfinite(a->gamma),
                  "point %d: Pi1 %.17g/%.17g gamma %.17g/%.17g impacts %ld/%ld", p, a->Pi1, b->Pi1,
                  a->gamma, b->gamma, a->impacts, b->impacts);
        }
        sweep_seen stop = {.stop_at = 3};
        rc = pd_spec_sweep(&s, sweep_point, &stop, &err);
        CHECK(ctx, rc == PD_ESTOPPED && err.status == PD_ESTOPPED && stop.calls == 3,
              "stop: rc %d, %d calls (%s)", rc, stop.calls, err.msg);
        CHECK(ctx, pd_spec_sweep(&s, NULL, NULL, NULL) == PD_OK, "no callback, no err");
    }
    pd_spectrum bad;
    pd_err err;
    sweep_seen seen = {0};
    pd_spec_init(&bad);
    int rc = pd_spec_sweep(&bad, sweep_point, &seen, &err);
    CHECK(ctx, rc == PD_EINVAL && strstr(err.msg, "Pi2") && seen.calls == 0,
          "no Pi2 grid: rc %d (%s), %d calls", rc, err.msg, seen.calls);
    bad.pi2_min = 0.5, bad.pi2_max = 2, bad.npi2 = 3, bad.eps[0] = 1.5;
    rc = pd_spec_sweep(&bad, sweep_point, &seen, &err);
    CHECK(ctx, rc == PD_EINVAL && strstr(err.msg, "eps") && seen.calls == 0,
          "eps 1.5: rc %d (%s), %d calls", rc, err.msg, seen.calls);
}

/* ---- tasks as a stream: the batch against single runs -------------------- */

/* What a stream returned. */
typedef struct stream_seen {
    long ntasks, next, calls, order_breaks;
    pd_spec_result *r;
    char (*msg)[256];
} stream_seen;

static long seen_next(void *ctx)
{
    stream_seen *w = ctx;
    return w->next < w->ntasks ? w->next++ : -1;
}

static void seen_done(void *ctx, long t, const pd_spec_result *r, const pd_err *err)
{
    stream_seen *w = ctx;
    w->order_breaks += t != w->calls;
    w->calls++;
    w->r[t] = *r;
    snprintf(w->msg[t], sizeof w->msg[t], "%s", r->status ? err->msg : "");
}

/* Every task of varied sweeps streamed (Moreau-Jean's run many at a time on
 * the batch's lanes, each lane refilled as its run ends) gives
 * pd_spec_run_task's figures bit for bit: pulses and the harmonic
 * excitation, the default step (one h per Pi2 above 1) and a common step,
 * theta, gamma, damping, restitution 0 and 1, the no-wall twins, a record;
 * the event-driven and penalty tasks too (run alone); a task that blows up
 * fails with pd_spec_run_task's status and message. */
static void stream_matches_single(pd_test_ctx *ctx);

/* The cases of an oscillator stream and what it reported. */
typedef struct osc_seen {
    pd_osc *c;
    pd_run_opts *o;
    long n, next, calls, batched;
    pd_osc_result *r;
    int *status;
} osc_seen;

static int osc_seen_next(void *ctx, pd_osc *c, pd_run_opts *o, long *id)
{
    osc_seen *w = ctx;
    if (w->next >= w->n)
        return 0;
    *c = w->c[w->next];
    *o = w->o[w->next];
    *id = w->next++;
    return 1;
}

static void osc_seen_done(void *ctx, long id, const pd_osc_result *r, int status, const pd_err *err)
{
    osc_seen *w = ctx;
    (void)err;
    w->calls++;
    w->r[id] = *r;
    w->status[id] = status;
    w->batched += status == 0 && r->kernel && strcmp(r->kernel, "batched") == 0;
}

/* The same double to the bit (the sign of a zero and NaNs' payload included). */
static int bits_same(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Every figure of a batched run to the bit: pd_osc_run's (cpu_s and the
 * kernel's name aside). */
static int osc_result_same(const pd_osc_result *a, const pd_osc_result *b)
{
    const double x[] = {a->umax,
                        a->u_toward,
                        a->u_away,
                        a->first_impact,
                        a->first_impact_velocity,
                        a->max_impact_velocity,
                        a->max_impulse,
                        a->contact_time,
                        a->min_gap,
                        a->dt,
                        a->tend,
                        a->theta,
                        a->gamma,
                        a->acc_max,
                        a->force_max,
                        a->force_equiv,
                        a->contact_duration};
    const double y[] = {b->umax,
                        b->u_toward,
                        b->u_away,
                        b->first_impact,
                        b->first_impact_velocity,
                        b->max_impact_velocity,
                        b->max_impulse,
                        b->contact_time,
                        b->min_gap,
                        b->dt,
                        b->tend,
                        b->theta,
                        b->gamma,
                        b->acc_max,
                        b->force_max,
                        b->force_equiv,
                        b->contact_duration};
    for (size_t i = 0; i < sizeof x / sizeof x[0]; i++)
        if (!bits_same(x[i], y[i]))
            return 0;
    return a->impacts == b->impacts && a->accumulations == b->accumulations && a->steps == b->steps;
}

/* pd_osc_run_stream against pd_osc_run case by case, every figure of the
 * result bit for bit (the impact velocities, the largest impulse and the
 * smallest gap too, which the sweep's results leave out): sine, cosine and
 * harmonic excitations (a window that opens late), both directions, gaps
 * from 0 (on the wall at rest) to 2, restitution 0, 0.5 and 1, no-wall
 * twins, a record, some of its runs with more steps than a force table
 * holds (lanes computing their own forces); the default steps (one per
 * Pi2 above 1) and common ones; then
 * theta = 0.7 with gamma = 0.3.  Most cases must run on the lanes. */
static void osc_stream_matches_run(pd_test_ctx *ctx)
{
    enum { NC = 240 };
    pd_record rec;
    memset(&rec, 0, sizeof rec);
    snprintf(rec.name, sizeof rec.name, "burst");
    rec.npts = 1201, rec.dt = 0.005;
    osc_seen w = {.n = NC};
    rec.acc = malloc((size_t)rec.npts * sizeof *rec.acc);
    w.c = malloc(NC * sizeof *w.c);
    w.o = malloc(NC * sizeof *w.o);
    w.r = calloc(NC, sizeof *w.r);
    w.status = calloc(NC, sizeof *w.status);
    if (!CHECK(ctx, rec.acc && w.c && w.o && w.r && w.status, "out of memory"))
        goto done;
    for (long k = 0; k < rec.npts; k++) /* a decaying burst, then rest */
        rec.acc[k] = k < 900 ? 3.0 * exp(-k / 300.0) * sin(PD_TWO_PI * k / 70.0) : 0.0;
    pd_record_pulse rp = {.ap = 2.0, .Tp = 0.35};
    static const double pi3[] = {0.0, 0.02, 0.3, 2.0}, eps[] = {0.0, 0.5, 1.0};
    static const pd_pulse pulses[] = {PD_PULSE_SINE, PD_PULSE_COSINE, PD_PULSE_HARMONIC};
    for (int pass = 0; pass < 2; pass++) {
        for (int i = 0; i < NC; i++) {
            pd_osc c = pd_osc_default();
            pd_run_opts o = pd_run_default_opts();
            o.method = PD_METHOD_MOREAU;
            o.no_demands = 1;
            c.pulse = pulses[i % 3];
            c.dir = (i / 3) % 2 ? -1 : 1;
            c.Pi2 = 0.15 * pow(1.25, i % 23);
            c.Pi3 = pi3[(i / 7) % 4];
            c.eps = eps[(i / 5) % 3];
            c.xi = (i / 11) % 2 ? 0.0 : 0.05;
            o.no_wall = i % 9 == 4;
            if (c.pulse == PD_PULSE_HARMONIC)
                o.dt = 0.004;  /* (the default step: Tp / 2000 over 38 s) */
            if (i % 13 == 6) { /* the record; some with more steps than a table holds */
                pd_osc_set_record(&c, &rec, &rp, 1.0 + 0.1 * (i % 3));
                o.dt = i % 26 == 6 ? 1.5e-4 : 2e-3;
            }
            if (pass == 1)
                o.theta = 0.7, o.gamma = 0.3;
            w.c[i] = c;
            w.o[i] = o;
        }
        w.next = w.calls = w.batched = 0;
        pd_err err;
        CHECK(ctx, pd_osc_run_stream(osc_seen_next, osc_seen_done, &w, &err) == PD_OK, "stream: %s",
              err.msg);
        CHECK(ctx, w.calls == NC, "pass %d: %ld of %d cases reported", pass, w.calls, NC);
        CHECK(ctx, w.batched > NC * 3 / 4, "pass %d: %ld of %d cases on the lanes", pass, w.batched,
              NC);
        long differ = 0, first = -1, impacts = 0;
        for (int i = 0; i < NC; i++) {
            pd_osc_result b;
            int rc = pd_osc_run(&w.c[i], &w.o[i], NULL, NULL, &b, &err);
            int bad = rc != w.status[i] || (rc == 0 && !osc_result_same(&w.r[i], &b));
            differ += bad;
            if (bad && first < 0)
                first = i;
            impacts += rc == 0 ? b.impacts : 0;
        }
        CHECK(ctx, differ == 0, "pass %d: %ld of %d cases differ from pd_osc_run (first: %ld)",
              pass, differ, NC, first);
        CHECK(ctx, impacts > 500, "pass %d: %ld impacts (the events' path must be exercised)", pass,
              impacts);
    }
done:
    free(rec.acc);
    free(w.c);
    free(w.o);
    free(w.r);
    free(w.status);
}

/* ... and pd_osc_run_stream's whole results against pd_osc_run's, with
 * each instruction set's batch this processor has (POUND_ISA caps
 * pd_cpu_level: every variant computes the scalar kernel's numbers). */
static void test_spectrum_stream_matches_single(pd_test_ctx *ctx)
{
    static const struct {
        const char *isa;
        int level;
    } variants[] = {{"avx512", 4}, {"avx2", 3}, {"baseline", 0}};
    const char *old = getenv("POUND_ISA");
    char saved[32];
    snprintf(saved, sizeof saved, "%s", old ? old : "");
    int have = pd_cpu_level(), ran = 0;
    for (int k = 0; k < 3; k++) {
        if (variants[k].level > have)
            continue;
        setenv("POUND_ISA", variants[k].isa, 1);
        CHECK(ctx, pd_cpu_level() == variants[k].level, "POUND_ISA=%s: level %d", variants[k].isa,
              pd_cpu_level());
        stream_matches_single(ctx);
        osc_stream_matches_run(ctx);
        ran++;
    }
    if (old)
        setenv("POUND_ISA", saved, 1);
    else
        unsetenv("POUND_ISA");
    CHECK(ctx, ran >= 1, "no variant ran");
}

static void stream_matches_single(pd_test_ctx *ctx)
{
    pd_record rec;
    memset(&rec, 0, sizeof rec);
    snprintf(rec.name, sizeof rec.name, "two pulses");
    rec.npts = 801, rec.dt = 0.005;
    rec.acc = malloc((size_t)rec.npts * sizeof *rec.acc);
    if (!CHECK(ctx, rec.acc != NULL, "out of memory"))
        return;
    for (long k = 0; k < rec.npts; k++) /* two sine cycles of 1 s and 0.5 s, then rest */
        rec.acc[k] = k < 200   ? -2.0 * sin(PD_TWO_PI * k / 200.0)
                     : k < 300 ? 1.5 * sin(PD_TWO_PI * (k - 200) / 100.0)
                               : 0.0;
    pd_record_pulse rp = {.ap = 2.0, .Tp = 1.0};
    long compared = 0, batched_impacts = 0;
    for (int v = 0; v < 6; v++) {
        pd_spectrum s;
        pd_spec_init(&s);
        s.opts.method = PD_METHOD_MOREAU;
        s.pi2_min = 0.1, s.pi2_max = 6, s.npi2 = 23;
        s.npulse = 2, s.pulse[1] = PD_PULSE_COSINE;
        s.ndir = 2, s.dir[1] = -1;
        s.nsize = 2, s.size[0] = 0.01, s.size[1] = 0.3;
        if (v == 1) { /* a common step, theta and gamma, damping and restitution lists */
            s.dt_per_Tp = 700;
            s.opts.theta = 0.8, s.opts.gamma = 0.2;
            s.nxi = 2, s.xi[0] = 0.0, s.xi[1] = 0.2;
            s.neps = 2, s.eps[0] = 0.0, s.eps[1] = 1.0;
        }
        if (v == 2) { /* the harmonic excitation: a long run, a late window */
            s.npulse = 1, s.pulse[0] = PD_PULSE_HARMONIC;
            s.pi2_min = 0.5, s.pi2_max = 4, s.npi2 = 9;
        }
        if (v == 3) { /* a record */
            pd_osc_set_record(&s.base, &rec, &rp, 1.0);
            s.npulse = 1, s.nap = 1, s.ap[0] = s.base.ap;
        }
        if (v == 4) /* the exact method: every task alone */
            s.opts.method = PD_METHOD_EVENT, s.npi2 = 6;
        if (v == 5) { /* an explicit scheme that blows up above some Pi2 */
            s.opts.theta = 0.0, s.opts.allow_unstable = 1;
            s.dt_per_Tp = 10, s.opts.tend = 30.0, s.npi2 = 12, s.pi2_max = 300;
        }
        long n = pd_spec_tasks(&s);
        stream_seen w = {.ntasks = n};
        w.r = calloc((size_t)n, sizeof *w.r);
        w.msg = calloc((size_t)n, sizeof *w.msg);
        if (!CHECK(ctx, w.r && w.msg, "out of memory")) {
            free(w.r);
            free(w.msg);
            break;
        }
        pd_err err;
        CHECK(ctx, pd_spec_stream(&s, seen_next, seen_done, &w, &err) == PD_OK, "stream: %s",
              err.msg);
        CHECK(ctx, w.calls == n, "sweep %d: %ld of %ld tasks reported", v, w.calls, n);
        long failed = 0, differ = 0;
        for (long t = 0; t < n; t++) {
            pd_spec_result a = w.r[t], b;
            pd_spec_run_task(&s, t, &b, &err);
            failed += b.status != 0;
            if (b.status || a.status) {
                differ += a.status != b.status || strcmp(w.msg[t], err.msg) != 0;
                continue;
            }
            differ += !(same(a.umax, b.umax) && same(a.u_toward, b.u_toward) &&
                        same(a.u_away, b.u_away) && same(a.contact_time, b.contact_time) &&
                        same(a.first_impact, b.first_impact) && a.impacts == b.impacts &&
                        a.steps == b.steps && a.done && signbit(a.u_away) == signbit(b.u_away));
            if (v < 4)
                batched_impacts += a.impacts;
            compared++;
        }
        CHECK(ctx, differ == 0, "sweep %d: %ld of %ld tasks differ from single runs", v, differ, n);
        if (v == 5)
            CHECK(ctx, failed > 0 && failed < n, "sweep 5 must fail in part (%ld of %ld)", failed,
                  n);
        if (v < 4)
            CHECK(ctx, w.order_breaks > 0,
                  "sweep %d: runs of different lengths end out of "
                  "order on the lanes (%ld)",
                  v, w.order_breaks);
        free(w.r);
        free(w.msg);
    }
    CHECK(ctx, compared > 1000 && batched_impacts > 1000, "%ld tasks compared, %ld impacts",
          compared, batched_impacts);
    free(rec.acc);
}

void suite_spectrum(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_spectrum_matches_simulate);
    PD_RUN(ctx, test_spectrum_threads_bit_identical);
    PD_RUN(ctx, test_spectrum_resume);
    PD_RUN(ctx, test_spectrum_bad_input);
    PD_RUN(ctx, test_spectrum_refuses_copies_without_mpi);
    PD_RUN(ctx, test_spectrum_hdf5_csv_read_back);
    PD_RUN(ctx, test_spectrum_linear_vs_log);
    PD_RUN(ctx, test_spectrum_twins_shared);
    PD_RUN(ctx, test_spectrum_dimensional_self_similar);
    PD_RUN(ctx, test_spectrum_plot);
    PD_RUN(ctx, test_spectrum_mpi_matches_serial);
    PD_RUN(ctx, test_spectrum_sweep_callback);
    PD_RUN(ctx, test_spectrum_stream_matches_single);
}
