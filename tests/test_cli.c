/* test_cli.c — the pound command line: bad input, output files, JSON. */
#include <hdf5.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "pd_problems.h"
#include "pd_test.h"

/* Every bad-input class: exit 2, one stderr line naming the flag, no file. */
static void test_cli_bad_input(pd_test_ctx *ctx)
{
    static const struct {
        const char *flag, *value, *named;
    } cases[] = {{"--gap", "-0.01", "gap"},
                 {"--eps", "1.5", "eps"},
                 {"--eps", "-0.2", "eps"},
                 {"--xi", "1.0", "xi"},
                 {"--xi", "-0.1", "xi"},
                 {"--dt", "0", "dt"},
                 {"--dt", "-1e-3", "dt"},
                 {"--T0", "nan", "T0"},
                 {"--T0", "0", "T0"},
                 {"--ap", "0", "ap"},
                 {"--Tp", "inf", "Tp"},
                 {"--pulse", "triangle", "pulse"},
                 {"--dir", "sideways", "dir"},
                 {"--theta", "0.3", "theta"},
                 {"--eps", "abc", "eps"},
                 {"--Pi3", "-1", "Pi3"},
                 {"--every", "0", "every"},
                 {"--bogus", "1", "bogus"},
                 {"--method", "magic", "method"},
                 {"--tend", "-2", "tend"},
                 {"--gamma", "2", "gamma"},
                 {"-o", "run.txt", "run.txt"},
                 {"--Piy", "-1", "Piy"},
                 {"--Piy", "nan", "Piy"},
                 {"--uy", "0", "uy"},
                 {"--alpha", "1.5", "alpha"},
                 {"--alpha", "0.2", "--uy or --Piy"}, /* alpha without a yield displacement */
                 {"--Pi2", "1", "Pi2"} /* with --T0: both given */};
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_cli_dirXXXXXX";
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    char out[512];
    snprintf(out, sizeof out, "%s/out.h5", dir);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *args[] = {
            "simulate", "--pulse",     "sine",         "--ap", "1",     "--Tp", "1",
            "--T0",     "1",           "--gap",        "0.01", "--eps", "0.5",  "-o",
            out,        cases[k].flag, cases[k].value, NULL};
        if (!strcmp(cases[k].flag, "--gap") || !strcmp(cases[k].flag, "--eps") ||
            !strcmp(cases[k].flag, "--T0")) { /* replace the base value instead of repeating */
            for (int i = 0; args[i]; i++)
                if (!strcmp(args[i], cases[k].flag)) {
                    args[i + 1] = cases[k].value;
                    args[15] = NULL;
                }
        }
        if (!strcmp(cases[k].flag, "--Pi3")) { /* --Pi3 alone: drop --gap */
            args[9] = "--xi";
            args[10] = "0.05";
        }
        if (!strcmp(cases[k].flag, "-o")) {
            args[13] = "-o";
            args[14] = cases[k].value;
            args[15] = NULL;
        }
        proc_out r;
        pd_test_pound(ctx, args, &r);
        char *nl = strchr(r.err, '\n');
        CHECK(ctx, r.status == 2, "%s %s: exit %d, expected 2 (stderr: %s)", cases[k].flag,
              cases[k].value, r.status, r.err);
        CHECK(ctx, strstr(r.err, cases[k].named) != NULL, "%s %s: message does not name %s: %s",
              cases[k].flag, cases[k].value, cases[k].named, r.err);
        CHECK(ctx, nl && nl[1] == '\0', "%s %s: stderr must be one line: %s", cases[k].flag,
              cases[k].value, r.err);
        CHECK(ctx, r.out[0] == '\0', "%s %s: nothing on stdout: %s", cases[k].flag, cases[k].value,
              r.out);
        CHECK(ctx, pd_test_dir_entries(dir) == 0, "%s %s: a file was left behind", cases[k].flag,
              cases[k].value);
        pd_test_proc_free(&r);
    }
    rmdir(dir);
}

/* Issue 11's refusals: overflowing and denormal values name the flag the
 * user typed (not a derived one), the event-driven reference refuses a
 * period it would take forever to scan (it hung), an empty method list is
 * refused (it exited 0), a theta just below 1/2 is quoted as given, and
 * control bytes from the command line never reach the terminal. */
static void test_cli_hardening(pd_test_ctx *ctx)
{
    static const struct {
        const char *args[12];
        const char *named;
    } cases[] = {
        {{"simulate", "--Tp", "1e308", NULL}, "--Tp"},
        {{"simulate", "--T0", "1e308", NULL}, "--T0"},
        {{"simulate", "--gap", "1e308", NULL}, "--gap"},
        {{"simulate", "--Pi2", "1e308", NULL}, "--Pi2"},
        {{"simulate", "--Pi2", "1e308", "--dt", "0.01", "--method", "event", NULL}, "--Pi2"},
        {{"simulate", "--Pi2", "1e8", "--dt", "0.01", "--method", "event", NULL}, "--Pi2"},
        {{"converge", "--dt", "1e-2:1e-3:2", "--Pi2", "1e308", NULL}, "--Pi2"},
        {{"simulate", "--ap", "4.9e-324", NULL}, "out of range"},
        {{"simulate", "--theta", "0.4999999", NULL}, "0.4999999"},
        {{"converge", "--dt", "1e-2:1e-3:2", "--methods", "", NULL}, "--methods"},
        {{"compare", "--methods", ",", NULL}, "--methods"},
        {{"simulate", "--pulse", "a\033[31mred", NULL}, "a?[31mred"},
        /* the flag the user typed, not the one whose derived value overflowed */
        {{"simulate", "--tend", "1e308", NULL}, "--tend"},
        /* Pi2 = Tp / T0 overflows: the extreme value is Tp's, not T0's */
        {{"simulate", "--pulse", "sine", "--ap", "4", "--Tp", "1e308", "--T0", "0.5", "--gap",
          "0.004", NULL},
         "--Tp:"},
        /* too many steps because of Tp (stress: derived): --Tp, not --T0 */
        {{"simulate", "--pulse", "sine", "--ap", "4", "--Tp", "1e30", "--T0", "0.5", "--gap",
          "0.004", NULL},
         "--Tp:"},
        {{"compare", "--pulse", "sine", "--ap", "4", "--Tp", "1e-30", "--T0", "0.5", "--gap",
          "0.004", NULL},
         "--Tp:"},
        {{"simulate", "--dt", "1e308", NULL}, "--dt"},
        {{"simulate", "--chain", "3", "--chain-ratio", "1e308", NULL}, "--chain-ratio"},
        {{"spectrum", "--Pi2", "1e-300:1e300:2", NULL}, "--Pi2"},
        {{"spectrum", "--Pi2", "0.5:1:2", "--gap", "1e308", NULL}, "--gap"},
        {{"spectrum", "--Pi2", "0.5:1:2", "--dt-per-Tp", "1e308", NULL}, "--dt-per-Tp"},
        {{"spectrum", "--Pi2", "0.5:1:2", "--tend", "1e308", NULL}, "--tend"},
        /* the penalty's tolerances: a relative one of 1 or more is refused */
        {{"simulate", "--method", "penalty", "--rtol", "0x10", NULL}, "--rtol"},
        /* conflicting flags, no command */
        {{"lcp", "x.lcp", "--all", "--index", "0", NULL}, "--index"},
        {{NULL}, "no command"}};
    if (!pd_test_have_pound(ctx))
        return;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        proc_out r;
        pd_test_pound(ctx, cases[k].args, &r);
        char *nl = strchr(r.err, '\n');
        CHECK(ctx,
              r.status == 2 && strstr(r.err, cases[k].named) && nl && nl[1] == '\0' &&
                  !strchr(r.err, '\033'),
              "case %zu (%s %s): exit %d, expected 2 and one line naming '%s': %s", k,
              cases[k].args[0] ? cases[k].args[0] : "", cases[k].args[0] ? cases[k].args[1] : "",
              r.status, cases[k].named, r.err);
        pd_test_proc_free(&r);
    }
}

/* -o run.h5: datasets t, u, v, impulse, gap with units, inputs and summary
 * as attributes, read back with the HDF5 library; the JSON agrees. */
static void test_cli_hdf5_output(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_cli_h5XXXXXX", path[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(path, sizeof path, "%s/run.h5", dir);
    const char *args[] = {"simulate", "--pulse", "cosine", "--dir",  "normal", "--ap",
                          "2",        "--Tp",    "0.5",    "--T0",   "0.6",    "--gap",
                          "0.002",    "--eps",   "0.7",    "--dt",   "1e-3",   "--every",
                          "3",        "-o",      path,     "--json", NULL};
    proc_out r;
    CHECK(ctx, pd_test_pound(ctx, args, &r) == 0, "exit %d: %s", r.status, r.err);
    double steps = pd_test_json_num(r.out, "steps", 0), umax = pd_test_json_num(r.out, "umax", 0);
    CHECK(ctx, steps == 1700, "steps %g (tend = Tp + 2 T0 = 1.7 s at dt 1e-3)", steps);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (!CHECK(ctx, f >= 0, "cannot open %s", path))
        goto done;
    const char *names[] = {"t", "u", "v", "impulse", "gap"};
    for (int k = 0; k < 5; k++) {
        hid_t ds = H5Dopen2(f, names[k], H5P_DEFAULT);
        hsize_t dims[1] = {0};
        if (!CHECK(ctx, ds >= 0, "dataset %s missing", names[k]))
            continue;
        hid_t sp = H5Dget_space(ds);
        H5Sget_simple_extent_dims(sp, dims, NULL);
        CHECK(ctx, dims[0] == 1700 / 3 + 1, "%s has %llu rows, expected %d", names[k],
              (unsigned long long)dims[0], 1700 / 3 + 1);
        CHECK(ctx, H5Aexists(ds, "units") > 0, "%s has no units attribute", names[k]);
        if (k == 1) { /* u: max |u| over the decimated rows <= umax, close to it */
            double *u = malloc(dims[0] * sizeof *u), m = 0;
            H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, u);
            for (hsize_t i = 0; i < dims[0]; i++)
                m = fmax(m, fabs(u[i]));
            CHECK(ctx, m <= umax && m > 0.95 * umax, "max |u| in file %g vs umax %g", m, umax);
            free(u);
        }
        H5Sclose(sp);
        H5Dclose(ds);
    }
    CHECK_NEAR(ctx, pd_test_h5_num(f, "umax"), umax, 0.0);
    CHECK_NEAR(ctx, pd_test_h5_num(f, "eps"), 0.7, 0.0);
    CHECK_NEAR(ctx, pd_test_h5_num(f, "Tp"), 0.5, 0.0);
    CHECK(ctx, H5Aexists(f, "umax_units") > 0 && H5Aexists(f, "pulse") > 0,
          "summary attributes with units");
    H5Fclose(f);
done:
    pd_test_proc_free(&r);
    unlink(path);
    rmdir(dir);
}

/* -o run.csv: the same columns; --json: first_impact null without impact,
 * Pi1 = umax wp^2 / ap. */
static void test_cli_csv_and_json(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_cli_csvXXXXXX", path[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(path, sizeof path, "%s/run.csv", dir);
    const char *args[] = {"simulate", "--pulse", "sine", "--ap",   "1",  "--Tp",
                          "1",        "--T0",    "1",    "--gap",  "10", "--dt",
                          "0.01",     "-o",      path,   "--json", NULL};
    proc_out r;
    CHECK(ctx, pd_test_pound(ctx, args, &r) == 0, "exit %d: %s", r.status, r.err);
    CHECK(ctx, strstr(r.out, "\"first_impact\":null") != NULL, "no impact: first_impact null");
    CHECK(ctx, pd_test_json_num(r.out, "impacts", 0) == 0, "impacts must be 0");
    double wp = 6.283185307179586, Pi1 = pd_test_json_num(r.out, "Pi1", 0),
           umax = pd_test_json_num(r.out, "umax", 0);
    CHECK_NEAR(ctx, Pi1, umax * wp * wp, 1e-12 * Pi1);
    CHECK_NEAR(ctx, pd_test_json_num(r.out, "gamma", 0), 1.0, 1e-15); /* no contact: same as free */
    char *text = pd_test_slurp(path);
    if (!CHECK(ctx, text != NULL, "cannot read %s", path))
        goto done;
    CHECK(ctx, strstr(text, "\nt,u,v,impulse,gap\n") != NULL, "CSV header row");
    CHECK(ctx, strstr(text, "# umax = ") != NULL && strstr(text, "[m]") != NULL,
          "CSV carries the summary with units");
    int rows = -1; /* newlines after the header row's own */
    for (char *p = strstr(text, "\nt,u,v"); p && *(++p);)
        rows += *p == '\n';
    CHECK(ctx, rows == 301, "CSV rows %d, expected 301 (t = 0 and 300 steps)", rows);
    free(text);
done:
    pd_test_proc_free(&r);
    unlink(path);
    rmdir(dir);
}

/* --flag=value is --flag value (getopt_long's form): the same JSON, for a
 * model flag, a list and a scene's path; an empty value is named; a token
 * that is a value (after a flag) is left whole.  A repeated --record is
 * refused (it would silently keep the last). */
static void test_cli_flag_equals_value(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    const char *eq[] = {"simulate", "--gap=0.004", "--Tp=0.3", "--method=event", "--json", NULL};
    const char *sp[] = {"simulate", "--gap", "0.004",  "--Tp", "0.3",
                        "--method", "event", "--json", NULL};
    const char *scene_eq[] = {"simulate", "--scene=examples/scenes/two-sdof.json", "--json", NULL};
    const char *scene_sp[] = {"simulate", "--scene", "examples/scenes/two-sdof.json", "--json",
                              NULL};
    const char *empty[] = {"simulate", "--gap=", NULL};
    proc_out a, b;
    for (int k = 0; k < 2; k++) {
        pd_test_pound(ctx, k ? scene_eq : eq, &a);
        pd_test_pound(ctx, k ? scene_sp : sp, &b);
        /* the runs' figures equal (the CPU times aside): umax and the impacts */
        CHECK(ctx,
              a.status == 0 && b.status == 0 &&
                  pd_test_json_num(a.out, "umax", 0) == pd_test_json_num(b.out, "umax", 0) &&
                  pd_test_json_num(a.out, "impacts", 0) == pd_test_json_num(b.out, "impacts", 0),
              "%s: exit %d / %d: %s", k ? "--scene=" : "--gap=", a.status, b.status, a.err);
        pd_test_proc_free(&a);
        pd_test_proc_free(&b);
    }
    pd_test_pound(ctx, empty, &a);
    CHECK(ctx, a.status == 2 && a.err && strstr(a.err, "--gap"), "--gap=: exit %d, %s", a.status,
          a.err);
    pd_test_proc_free(&a);
    /* a second --record makes a suite of both (it once silently replaced the
     * first): each is read, a missing one named on one line, exit 2 */
    const char *twice[] = {"simulate", "--record", "examples/records/NGA_no_1063_RRS228.AT2",
                           "--record=other.AT2", NULL};
    pd_test_pound(ctx, twice, &a);
    CHECK(ctx,
          a.status == 2 && a.err && strstr(a.err, "other.AT2: cannot open") &&
              strchr(a.err, '\n') == strrchr(a.err, '\n'),
          "--record twice: exit %d, %s", a.status, a.err);
    pd_test_proc_free(&a);
}

/* A yielding oscillator from the command line: --uy in metres is Piy Le,
 * the JSON adds the yielding figures (ductility = umax / uy, the energy
 * residual at rounding), the CSV's summary carries them, the elastic
 * run's JSON has none of them; a method that does not model yielding is
 * refused naming the flag (exit 2, one line). */
static void test_cli_yielding(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_cli_yieldXXXXXX", path[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(path, sizeof path, "%s/run.csv", dir);
    const char *args[] = {"simulate", "--ap",   "2",        "--Tp",   "0.5",
                          "--uy",     "0.003",  "--alpha",  "0.05",   "-o",
                          path,       "--json", "--method", "moreau", NULL};
    proc_out r;
    CHECK(ctx, pd_test_pound(ctx, args, &r) == 0, "exit %d: %s", r.status, r.err);
    double Le = 2.0 * 0.25 / (4.0 * 9.869604401089358), umax = pd_test_json_num(r.out, "umax", 0);
    CHECK_NEAR(ctx, pd_test_json_num(r.out, "Piy", 0), 0.003 / Le, 1e-12 * 0.003 / Le);
    CHECK_NEAR(ctx, pd_test_json_num(r.out, "ductility", 0), umax / 0.003, 1e-12 * umax / 0.003);
    CHECK(ctx,
          pd_test_json_num(r.out, "n_yield", 0) >= 1 &&
              fabs(pd_test_json_num(r.out, "energy_residual", 0)) <= 1e-12,
          "onsets %g, energy residual %g", pd_test_json_num(r.out, "n_yield", 0),
          pd_test_json_num(r.out, "energy_residual", 0));
    char *text = pd_test_slurp(path);
    CHECK(ctx, text && strstr(text, "# ductility = ") && strstr(text, "# residual = "),
          "the CSV's summary carries the yielding figures");
    free(text);
    pd_test_proc_free(&r);
    const char *elastic[] = {"simulate", "--json", NULL};
    CHECK(ctx, pd_test_pound(ctx, elastic, &r) == 0 && !strstr(r.out, "ductility"),
          "an elastic run's JSON reports no yielding: %s", r.out);
    pd_test_proc_free(&r);
    /* an overdamped slide (xi^2 = 0.0025 > alpha): not the exact reference's */
    const char *refused[] = {"simulate", "--Piy",    "0.5",   "--alpha",
                             "0.002",    "--method", "event", NULL};
    pd_test_pound(ctx, refused, &r);
    char *nl = strchr(r.err, '\n');
    CHECK(ctx, r.status == 2 && strstr(r.err, "--Piy") && nl && nl[1] == '\0',
          "--Piy with --method event: exit %d, %s", r.status, r.err);
    pd_test_proc_free(&r);
    unlink(path);
    rmdir(dir);
}

/* A run that fails mid-way (theta < 1/2 at a huge step) exits 1, names the
 * time, and leaves no file. */
static void test_cli_failed_run_leaves_no_file(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    char dir[] = "/tmp/pd_cli_failXXXXXX", path[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(path, sizeof path, "%s/run.h5", dir);
    const char *args[] = {
        "simulate",         "--Tp", "1",   "--T0",   "1",    "--Pi3", "1e6", "--theta", "0",
        "--allow-unstable", "--dt", "0.5", "--tend", "2000", "-o",    path,  NULL};
    proc_out r;
    pd_test_pound(ctx, args, &r);
    CHECK(ctx, r.status == 1, "exit %d, expected 1 (%s)", r.status, r.err);
    CHECK(ctx, strstr(r.err, "non-finite") && strstr(r.err, "t = "), "message: %s", r.err);
    CHECK(ctx, pd_test_dir_entries(dir) == 0, "a file was left behind");
    pd_test_proc_free(&r);
    rmdir(dir);
}

/* converge's lists refuse empty elements (they were skipped: exit 0):
 * exit 2, one line naming the flag and the list with the empty element's
 * place, nothing on stdout. */
static void test_cli_converge_empty_list_elements(pd_test_ctx *ctx)
{
    static const struct {
        const char *flag, *list, *named;
    } cases[] = {{"--methods", "moreau,", "element 2 of 'moreau,' is empty"},
                 {"--methods", ",moreau", "element 1 of ',moreau' is empty"},
                 {"--methods", "moreau,,penalty", "element 2 of 'moreau,,penalty' is empty"},
                 {"--theta", "0.5,", "element 2 of '0.5,' is empty"},
                 {"--theta", ",0.5", "element 1 of ',0.5' is empty"},
                 {"--theta", "0.5,,1", "element 2 of '0.5,,1' is empty"},
                 {"--kcs", "1e2,", "element 2 of '1e2,' is empty"},
                 {"--kcs", "1e2,,1e3", "element 2 of '1e2,,1e3' is empty"},
                 {"--kcs", ",", "element 1 of ',' is empty"},
                 {"--methods", "", "--methods"},
                 {"--theta", "", "--theta: empty list"}};
    if (!pd_test_have_pound(ctx))
        return;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const char *args[] = {"converge",       "--dt",        "1e-2:1e-3:2", "--methods",
                              "moreau,penalty", cases[k].flag, cases[k].list, NULL};
        proc_out r;
        pd_test_pound(ctx, args, &r);
        char *nl = strchr(r.err, '\n');
        CHECK(ctx, r.status == 2, "%s '%s': exit %d, expected 2 (%s)", cases[k].flag, cases[k].list,
              r.status, r.err);
        CHECK(ctx,
              strstr(r.err, cases[k].flag) && strstr(r.err, cases[k].named) && nl && nl[1] == '\0',
              "%s '%s': one line naming '%s': %s", cases[k].flag, cases[k].list, cases[k].named,
              r.err);
        CHECK(ctx, r.out[0] == '\0', "%s '%s': stdout '%s'", cases[k].flag, cases[k].list, r.out);
        pd_test_proc_free(&r);
    }
}

/* `pound --version`: exit 0, "pound VERSION" first (the header's), the
 * libraries it was built with, nothing on stderr; `pound --help` lists it
 * and `help`. */
static void test_cli_version(pd_test_ctx *ctx)
{
    const char *args[] = {"--version", NULL}, *hargs[] = {"--help", NULL};
    char first[64];
    proc_out r, h;
    if (!pd_test_have_pound(ctx))
        return;
    pd_test_pound(ctx, args, &r);
    snprintf(first, sizeof first, "pound %s\n", PD_VERSION);
    CHECK(ctx, r.status == 0 && r.err[0] == '\0', "exit %d, stderr '%s'", r.status, r.err);
    CHECK(ctx, !strncmp(r.out, first, strlen(first)), "first line '%s', expected '%s'", r.out,
          first);
    CHECK(ctx, strstr(r.out, "GSL ") && strstr(r.out, "HDF5 "), "no GSL/HDF5 versions: %s", r.out);
    pd_test_pound(ctx, hargs, &h);
    CHECK(ctx, h.status == 0 && strstr(h.out, "--version") && strstr(h.out, "help"),
          "--help: exit %d, lists --version and help: %s", h.status, h.out);
    pd_test_proc_free(&r);
    pd_test_proc_free(&h);
}

/* `pound help COMMAND` is `pound COMMAND --help` for every command (same
 * output, exit 0); an unknown command: exit 2, one line naming it, nothing
 * on stdout. */
static void test_cli_help_command(pd_test_ctx *ctx)
{
    static const char *const cmds[] = {"simulate", "compare", "converge", "spectrum",
                                       "record",   "lcp",     "bench"};
    if (!pd_test_have_pound(ctx))
        return;
    for (size_t k = 0; k < sizeof cmds / sizeof cmds[0]; k++) {
        const char *a[] = {"help", cmds[k], NULL}, *b[] = {cmds[k], "--help", NULL};
        proc_out ra, rb;
        pd_test_pound(ctx, a, &ra);
        pd_test_pound(ctx, b, &rb);
        CHECK(ctx, ra.status == 0 && rb.status == 0, "%s: exit %d and %d", cmds[k], ra.status,
              rb.status);
        CHECK(ctx, !strcmp(ra.out, rb.out) && !strncmp(ra.out, "usage: pound ", 13),
              "help %s differs from %s --help", cmds[k], cmds[k]);
        pd_test_proc_free(&ra);
        pd_test_proc_free(&rb);
    }
    const char *bad[] = {"help", "bogus", NULL};
    proc_out r;
    pd_test_pound(ctx, bad, &r);
    char *nl = strchr(r.err, '\n');
    CHECK(ctx, r.status == 2, "help bogus: exit %d, expected 2", r.status);
    CHECK(ctx, strstr(r.err, "'bogus'") && nl && nl[1] == '\0' && r.out[0] == '\0',
          "help bogus: one line naming it: '%s', stdout '%s'", r.err, r.out);
    pd_test_proc_free(&r);
}

/* The default method: the exact event-driven reference for one oscillator
 * (pulses and records), Moreau-Jean for scenes; a flag only one method
 * takes chooses it; two methods' flags need --method; the output says
 * which method ran and why.  The oscillator's default equals --method
 * event to the bit, and pd_osc_method falls back to Moreau-Jean where the
 * exact reference's scan would be over its budget. */
static void test_cli_default_method(pd_test_ctx *ctx)
{
    static const struct {
        const char *args[8];
        const char *method, *by;
    } cases[] = {
        {{"simulate", "--json"}, "event", "default"},
        {{"simulate", "--method", "auto", "--json"}, "event", "default"},
        {{"simulate", "--method", "moreau", "--json"}, "moreau", "--method"},
        {{"simulate", "--theta", "0.6", "--json"}, "moreau", "--theta"},
        {{"simulate", "--dt", "1e-3", "--json"}, "moreau", "--dt"},
        {{"simulate", "--kc", "1e5", "--json"}, "penalty", "--kc"},
        {{"simulate", "--no-accumulation", "--json"}, "event", "--no-accumulation"},
        {{"simulate", "--chain", "2", "--json"}, "moreau", "default"},
        {{"spectrum", "--Pi2", "0.5:2:3", "--json"}, "event", "default"},
        {{"spectrum", "--Pi2", "0.5:2:3", "--dt-per-Tp", "500", "--json"}, "moreau", "--dt-per-Tp"},
    };
    if (!pd_test_have_pound(ctx))
        return;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        proc_out r;
        char method[32] = "", by[32] = "";
        pd_test_pound(ctx, cases[k].args, &r);
        pd_test_json_str(r.out, "method", 0, method, sizeof method);
        pd_test_json_str(r.out, "method_by", 0, by, sizeof by);
        CHECK(ctx, r.status == 0 && !strcmp(method, cases[k].method) && !strcmp(by, cases[k].by),
              "%s %s: exit %d, method %s (%s), expected %s (%s): %s", cases[k].args[0],
              cases[k].args[1], r.status, method, by, cases[k].method, cases[k].by, r.err);
        pd_test_proc_free(&r);
    }
    /* the default is --method event, bit for bit; the text names it */
    const char *d[] = {"simulate", "--pulse", "cosine", "--Pi2", "2.5", "--json", NULL};
    const char *e[] = {"simulate", "--pulse", "cosine", "--Pi2", "2.5",
                       "--method", "event",   "--json", NULL};
    const char *t[] = {"simulate", NULL};
    proc_out rd, re, rt;
    pd_test_pound(ctx, d, &rd);
    pd_test_pound(ctx, e, &re);
    pd_test_pound(ctx, t, &rt);
    CHECK(ctx,
          pd_test_json_num(rd.out, "umax", 0) == pd_test_json_num(re.out, "umax", 0) &&
              pd_test_json_num(rd.out, "umax", 0) > 0.0,
          "default umax %.17g vs --method event %.17g", pd_test_json_num(rd.out, "umax", 0),
          pd_test_json_num(re.out, "umax", 0));
    CHECK(ctx, strstr(rt.out, "method    = event (the default for one oscillator"),
          "the text output names the default: %s", rt.out);
    pd_test_proc_free(&rd);
    pd_test_proc_free(&re);
    pd_test_proc_free(&rt);
    /* two methods' flags: exit 2 naming both */
    const char *both[] = {"simulate", "--theta", "0.6", "--kc", "1e5", NULL};
    proc_out rb;
    pd_test_pound(ctx, both, &rb);
    CHECK(ctx,
          rb.status == 2 && strstr(rb.err, "--theta") && strstr(rb.err, "--kc") &&
              strstr(rb.err, "--method"),
          "--theta with --kc: exit %d: %s", rb.status, rb.err);
    pd_test_proc_free(&rb);
    /* over the exact reference's budget, the default is Moreau-Jean */
    pd_osc c = pd_osc_default();
    pd_run_opts o = pd_run_default_opts();
    c.Pi2 = 1e6;
    CHECK(ctx, pd_osc_method(&c, &o) == PD_METHOD_MOREAU, "Pi2 = 1e6: %s",
          pd_method_name(pd_osc_method(&c, &o)));
    c.Pi2 = 3.0;
    CHECK(ctx, pd_osc_method(&c, &o) == PD_METHOD_EVENT, "Pi2 = 3: %s",
          pd_method_name(pd_osc_method(&c, &o)));
    o.method = PD_METHOD_PENALTY;
    CHECK(ctx, pd_osc_method(&c, &o) == PD_METHOD_PENALTY, "a method given is kept");
}

void suite_cli(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_cli_bad_input);
    PD_RUN(ctx, test_cli_hardening);
    PD_RUN(ctx, test_cli_hdf5_output);
    PD_RUN(ctx, test_cli_csv_and_json);
    PD_RUN(ctx, test_cli_flag_equals_value);
    PD_RUN(ctx, test_cli_yielding);
    PD_RUN(ctx, test_cli_failed_run_leaves_no_file);
    PD_RUN(ctx, test_cli_converge_empty_list_elements);
    PD_RUN(ctx, test_cli_version);
    PD_RUN(ctx, test_cli_help_command);
    PD_RUN(ctx, test_cli_default_method);
}
