/* test_harden.c — the fourth hardening round's regressions (issue 29): each
 * case failed before its fix. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hdf5_hl.h>

#include "pd_test.h"

/* Two SDOFs 2 cm apart under a cosine pulse (examples/scenes/two-sdof.json),
 * the second's storey height h (0: the default). */
static pd_scene *two_sdof(pd_test_ctx *ctx, double h)
{
    pd_scene_excitation exc = {.pulse = PD_PULSE_COSINE, .dir = 1, .ap = 3.0, .Tp = 0.6};
    pd_scene *sc = pd_scene_new(&exc);
    pd_err e;
    if (!CHECK(ctx, sc != NULL, "out of memory"))
        return NULL;
    if (!CHECK(ctx,
               !pd_scene_add_sdof(sc, "stiff", 0.4, 0.05, 2e5, &e) &&
                   !pd_scene_add_sdof(sc, "flexible", 1.2, 0.05, 1e5, &e) &&
                   (h == 0.0 || !pd_scene_set_heights(sc, &h, &e)) &&
                   !pd_scene_add_contact(sc, 0, 1, 1, 1, 0.02, 0.65, 0, &e) &&
                   !pd_scene_finish(sc, &e),
               "scene: %s", e.msg)) {
        pd_scene_free(sc);
        return NULL;
    }
    return sc;
}

/* Defect 4: a derived demand that overflows (the equivalent force pi I /
 * (2 td) of td = 1e-307 s, the drift ratio of a 5e-324 m storey) is refused
 * naming its input, not reported as success with inf. */
static void test_harden_derived_overflow(pd_test_ctx *ctx)
{
    pd_scene *sc = two_sdof(ctx, 0.0);
    if (!sc)
        return;
    pd_scene_result r;
    pd_err e;
    if (!CHECK(ctx, !pd_scene_result_alloc(sc, &r, &e), "%s", e.msg)) {
        pd_scene_free(sc);
        return;
    }
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_EVENT;
    int rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
    CHECK(ctx, rc == PD_OK && isfinite(r.force_equiv[0]) && r.force_equiv[0] > 0.0,
          "the default duration: rc %d, force %g", rc, r.force_equiv[0]);
    o.contact_duration = 1e-307;
    rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
    CHECK(ctx, rc == PD_EINVAL && strstr(e.msg, "contact-duration"),
          "td 1e-307: rc %d (%s), force %g", rc, e.msg, r.force_equiv[0]);
    pd_scene_result_free(&r);
    pd_scene_free(sc);

    /* the storey height: the last structure's */
    sc = two_sdof(ctx, 5e-324);
    if (!sc)
        return;
    rc = pd_scene_result_alloc(sc, &r, &e);
    if (CHECK(ctx, rc == PD_OK, "%s", e.msg)) {
        o.contact_duration = 0.0;
        rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
        CHECK(ctx, rc == PD_EINVAL && strstr(e.msg, "storey_heights") && strstr(e.msg, "flexible"),
              "height 5e-324: rc %d (%s), drift ratio %g", rc, e.msg, r.drift_ratio[1]);
        pd_scene_result_free(&r);
    }
    pd_scene_free(sc);
}

/* A scene file of two SDOFs, the second named `name`, in dir: its path. */
static int write_scene(const char *dir, const char *name, char *path, size_t cap)
{
    snprintf(path, cap, "%s/scene.json", dir);
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    fprintf(f,
            "{\"excitation\": {\"pulse\": \"cosine\", \"dir\": \"+x\", \"ap\": 3.0, \"Tp\": 0.6},\n"
            " \"structures\": [{\"name\": \"stiff\", \"T0\": 0.4, \"xi\": 0.05, \"mass\": 2e5},\n"
            "                {\"name\": \"%s\", \"T0\": 1.2, \"xi\": 0.05, \"mass\": 1e5}],\n"
            " \"contacts\": [{\"a\": \"stiff\", \"b\": \"%s\", \"gap\": 0.02, \"eps\": 0.65}],\n"
            " \"tend\": 2.0}\n",
            name, name);
    return fclose(f) ? -1 : 0;
}

/* Defect 5: structures named as the file's dimensions (t, storey) keep
 * their HDF5 output; t's scale is the root's. */
static void test_harden_h5_dimension_names(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    const char *names[] = {"t", "storey", "x"};
    for (int k = 0; k < 3; k++) {
        char dir[] = "/tmp/pd_harden_XXXXXX", scene[512], out[512];
        if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
            return;
        snprintf(out, sizeof out, "%s/o.h5", dir);
        if (CHECK(ctx, write_scene(dir, names[k], scene, sizeof scene) == 0, "scene file")) {
            const char *args[] = {"simulate", "--scene", scene, "-o", out, NULL};
            proc_out r;
            pd_test_pound(ctx, args, &r);
            CHECK(ctx, r.status == 0, "structure '%s': exit %d: %s", names[k], r.status, r.err);
            pd_test_proc_free(&r);
            H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
            hid_t f = H5Fopen(out, H5F_ACC_RDONLY, H5P_DEFAULT);
            char path[128];
            snprintf(path, sizeof path, "structures/%s/x", names[k]);
            hid_t ds = f >= 0 ? H5Dopen2(f, path, H5P_DEFAULT) : -1;
            hid_t t = f >= 0 ? H5Dopen2(f, "t", H5P_DEFAULT) : -1;
            CHECK(ctx, ds >= 0 && t >= 0 && H5DSis_attached(ds, t, 0) > 0,
                  "structure '%s': %s not on the root's t", names[k], path);
            if (ds >= 0)
                H5Dclose(ds);
            if (t >= 0)
                H5Dclose(t);
            if (f >= 0)
                H5Fclose(f);
        }
        pd_test_rm_dir(dir);
    }
}

/* Defect 7: a soft CPU limit (SIGXCPU) ends pound without its temporary
 * output file, as SIGTERM does. */
static void test_harden_cpu_limit_cleans_up(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    if (access("/usr/bin/prlimit", X_OK) != 0) {
        pd_test_skip(ctx, "no /usr/bin/prlimit");
        return;
    }
    char dir[] = "/tmp/pd_harden_XXXXXX", out[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(out, sizeof out, "%s/o.h5", dir);
    /* about a minute of CPU: the limit of 1 s falls inside the run */
    const char *argv[] = {"/usr/bin/prlimit",
                          "--cpu=1:60",
                          ctx->pound,
                          "simulate",
                          "--chain",
                          "100",
                          "--method",
                          "moreau",
                          "--dt",
                          "1e-6",
                          "--every",
                          "1000",
                          "-o",
                          out,
                          NULL};
    proc_out r;
    pd_test_spawn(argv, NULL, &r);
    CHECK(ctx, r.status == -1, "exit %d, expected death by SIGXCPU: %s", r.status, r.err);
    CHECK(ctx, pd_test_dir_entries(dir) == 0, "%d files left in %s", pd_test_dir_entries(dir), dir);
    pd_test_proc_free(&r);
    pd_test_rm_dir(dir);
}

/* One run of pound (args after the binary, env as pd_test_spawn's): exit 2
 * and one line naming `named`. */
static void refused(pd_test_ctx *ctx, const char *const *args, const char *env, const char *named)
{
    const char *argv[16] = {ctx->pound};
    for (int i = 0; args[i] && i < 14; i++)
        argv[i + 1] = args[i];
    proc_out r;
    pd_test_spawn(argv, env, &r);
    char *nl = strchr(r.err, '\n');
    CHECK(ctx, r.status == 2 && strstr(r.err, named) && nl && nl[1] == '\0',
          "%s %s (%s): exit %d, expected 2 and one line naming '%s': %s", args[0], args[1],
          env ? env : "", r.status, named, r.err);
    pd_test_proc_free(&r);
}

/* Defect 10: a shared folder the user names and a POUND_ISA naming no
 * instruction set are refused, not skipped or ignored. */
static void test_harden_bench_shared_and_isa(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    refused(ctx, (const char *[]){"bench", "--lcp", "--shared", "/nonexistent", NULL}, NULL,
            "--shared /nonexistent");
    refused(ctx, (const char *[]){"simulate", "--json", NULL}, "POUND_ISA=avx3", "POUND_ISA");
    refused(ctx, (const char *[]){"spectrum", "--Pi2", "0.5:1:2", NULL}, "POUND_ISA=", "POUND_ISA");
}

/* Defect 9: Newmark's step budget refused up front naming the flag that
 * made the steps too many; another method's flags refused with --method. */
static void test_harden_method_flags(pd_test_ctx *ctx)
{
    if (!pd_test_have_pound(ctx))
        return;
    refused(ctx, (const char *[]){"simulate", "--method", "newmark", "--kc", "1e300", NULL}, NULL,
            "kc:");
    refused(ctx, (const char *[]){"simulate", "--method", "newmark", "--dt", "1e-8", NULL}, NULL,
            "dt:");
    refused(ctx,
            (const char *[]){"simulate", "--scene", "examples/scenes/two-sdof.json", "--method",
                             "newmark", "--kc", "1e300", NULL},
            NULL, "kc:");
    refused(ctx, (const char *[]){"simulate", "--method", "moreau", "--close-tol", "1e-9", NULL},
            NULL, "--close-tol");
    refused(ctx, (const char *[]){"simulate", "--method", "newmark", "--theta", "0.6", NULL}, NULL,
            "--theta");
    refused(ctx, (const char *[]){"simulate", "--method", "event", "--kc", "10", NULL}, NULL,
            "--kc");
    refused(ctx, (const char *[]){"simulate", "--method", "newmark", "--stepper", "rk4imp", NULL},
            NULL, "--stepper");
    /* defect 4's other face: an excitation whose impacts' equivalent force
     * overflows at any duration names the excitation, not the duration */
    refused(ctx, (const char *[]){"simulate", "--ap", "1e308", NULL}, NULL, "--ap:");
    /* what each method reads stays accepted */
    const char *ok[][10] = {{"simulate", "--method", "newmark", "--kc", "10", NULL},
                            {"simulate", "--method", "penalty", "--stepper", "rk4imp", NULL},
                            {"simulate", "--method", "event", "--dt", "0.01", NULL},
                            {"simulate", "--chain", "3", "--method", "moreau", "--rtol", "1e-3",
                             "--close-tol", "1e-9", NULL}};
    for (size_t k = 0; k < sizeof ok / sizeof ok[0]; k++) {
        proc_out r;
        pd_test_pound(ctx, ok[k], &r);
        CHECK(ctx, r.status == 0, "%s %s %s: exit %d: %s", ok[k][1], ok[k][2], ok[k][3], r.status,
              r.err);
        pd_test_proc_free(&r);
    }
}

/* A row of n SDOFs (T0, xi, mass) between walls when walls (n + 1 contacts
 * of gap, eps), or free at both ends (n - 1 contacts), under a pulse. */
static pd_scene *row_of(pd_test_ctx *ctx, int n, const double *T0, const double *xi,
                        const double *mass, const double *gap, const double *eps, int walls,
                        pd_pulse pulse, double ap, double Tp, double tend)
{
    pd_scene_excitation exc = {.pulse = pulse, .dir = 1, .ap = ap, .Tp = Tp};
    pd_scene *sc = pd_scene_new(&exc);
    pd_err e;
    int rc = sc ? PD_OK : PD_ENOMEM, k = 0;
    char name[16];
    for (int i = 0; i < n && !rc; i++) {
        snprintf(name, sizeof name, "S%d", i);
        rc = pd_scene_add_sdof(sc, name, T0[i], xi[i], mass[i], &e);
    }
    if (walls && !rc)
        rc = pd_scene_add_contact(sc, PD_WALL, 0, 0, 1, gap[k], eps[k], k, &e), k++;
    for (int i = 0; i + 1 < n && !rc; i++, k++)
        rc = pd_scene_add_contact(sc, i, 1, i + 1, 1, gap[k], eps[k], k, &e);
    if (walls && !rc)
        rc = pd_scene_add_contact(sc, n - 1, 1, PD_WALL, 0, gap[k], eps[k], k, &e);
    if (!rc)
        sc->tend = tend;
    if (!CHECK(ctx, !rc && !pd_scene_finish(sc, &e), "scene: %s", sc ? e.msg : "no memory")) {
        pd_scene_free(sc);
        return NULL;
    }
    return sc;
}

/* Defects 2 and 3: gaps within the closing tolerance (1e-300, the smallest
 * subnormal) are closed: the row reference runs them as the row at gap 0
 * (10 impacts, in milliseconds) instead of exhausting its budget of events
 * or failing its first LCP; a light body between heavy ones beyond what
 * double precision resolves is refused up front naming the method that
 * runs it. */
static void test_harden_gaps_within_tolerance(pd_test_ctx *ctx)
{
    const double gaps[] = {0.0, 1e-300, 5e-324, 1e-12};
    pd_scene_result r0, r;
    pd_err e;
    /* ten SDOFs (T0 1 s) between two walls, every gap g, eps 0.7, a sine pulse */
    double T0[10], xi[10], mass[10], g[11], eps[11];
    for (int i = 0; i < 11; i++) {
        if (i < 10)
            T0[i] = 1.0, xi[i] = 0.05, mass[i] = 1e5;
        eps[i] = 0.7;
    }
    for (int k = 0; k < 4; k++) {
        for (int i = 0; i < 11; i++)
            g[i] = gaps[k];
        pd_scene *sc = row_of(ctx, 10, T0, xi, mass, g, eps, 1, PD_PULSE_SINE, 3.0, 1.0, 3.0);
        if (!sc || !CHECK(ctx, !pd_scene_result_alloc(sc, &r, &e), "%s", e.msg)) {
            pd_scene_free(sc);
            continue;
        }
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        int rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
        CHECK(ctx, rc == PD_OK, "gap %g: %s", gaps[k], e.msg);
        if (k == 0)
            r0 = r;
        else {
            if (rc == PD_OK)
                for (int i = 0; i < r.n; i++)
                    CHECK(ctx, r.umax[i] == r0.umax[i], "gap %g: umax %d = %.17g, at gap 0 %.17g",
                          gaps[k], i, r.umax[i], r0.umax[i]);
            pd_scene_result_free(&r);
        }
        pd_scene_free(sc);
    }
    if (r0.umax)
        pd_scene_result_free(&r0);

    /* masses 1e-6 and 1e12 kg touching: refused for the references, run by Moreau-Jean */
    pd_scene_excitation exc = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 3.0, .Tp = 1.0};
    pd_scene *sc = pd_scene_new(&exc);
    if (!CHECK(ctx,
               sc && !pd_scene_add_sdof(sc, "A", 1.0, 0.05, 1e-6, &e) &&
                   !pd_scene_add_sdof(sc, "B", 1.0, 0.05, 1e12, &e) &&
                   !pd_scene_add_contact(sc, PD_WALL, 0, 0, 1, 1e-300, 1.0, 0, &e) &&
                   !pd_scene_add_contact(sc, 0, 1, 1, 1, 1e-300, 1.0, 1, &e) &&
                   !pd_scene_add_contact(sc, 1, 1, PD_WALL, 0, 1e-300, 1.0, 2, &e) &&
                   !pd_scene_finish(sc, &e) && !pd_scene_result_alloc(sc, &r, &e),
               "scene: %s", e.msg)) {
        pd_scene_free(sc);
        return;
    }
    const pd_method methods[] = {PD_METHOD_EVENT, PD_METHOD_EVENT_GENERAL, PD_METHOD_MOREAU};
    for (int k = 0; k < 3; k++) {
        pd_run_opts o = pd_run_default_opts();
        o.method = methods[k];
        int rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
        if (k < 2)
            CHECK(ctx, rc == PD_EINVAL && strstr(e.msg, "mass") && strstr(e.msg, "moreau"),
                  "%s: rc %d: %s", pd_method_name(methods[k]), rc, e.msg);
        else
            CHECK(ctx, rc == PD_OK, "moreau: %s", e.msg);
    }
    pd_scene_result_free(&r);
    pd_scene_free(sc);
}

/* Defect 6: under an address-space limit a scene of 1000 bodies written to
 * HDF5 ends with "out of memory" (exit 1), never a signal, and leaves no
 * file.  (Skipped under AddressSanitizer, whose shadow memory needs more
 * address space than any such limit.) */
static void test_harden_memory_limit(pd_test_ctx *ctx)
{
#if defined(__SANITIZE_ADDRESS__)
    pd_test_skip(ctx, "AddressSanitizer");
    return;
#endif
    if (!pd_test_have_pound(ctx))
        return;
    if (access("/usr/bin/prlimit", X_OK) != 0) {
        pd_test_skip(ctx, "no /usr/bin/prlimit");
        return;
    }
    char dir[] = "/tmp/pd_harden_XXXXXX", scene[512], out[512];
    if (!CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp"))
        return;
    snprintf(scene, sizeof scene, "%s/cradle.json", dir);
    snprintf(out, sizeof out, "%s/o.h5", dir);
    FILE *f = fopen(scene, "w");
    if (f) {
        fprintf(f,
                "{\"excitation\": {\"pulse\": \"sine\", \"dir\": \"+x\", \"ap\": 3, \"Tp\": 1},\n"
                " \"tend\": 2, \"structures\": [");
        for (int i = 0; i < 1000; i++)
            fprintf(f, "%s{\"name\": \"S%d\", \"T0\": 1, \"xi\": 0.05, \"mass\": 1e5}",
                    i ? ", " : "", i);
        fprintf(
            f, "],\n \"contacts\": [{\"a\": \"wall\", \"b\": \"S0\", \"gap\": 0.01, \"eps\": 0.9}");
        for (int i = 0; i + 1 < 1000; i++)
            fprintf(f, ", {\"a\": \"S%d\", \"b\": \"S%d\", \"gap\": 0, \"eps\": 0.9}", i, i + 1);
        fprintf(f, "]}\n");
    }
    if (CHECK(ctx, f && fclose(f) == 0, "scene file")) {
        const char *limits[] = {"--as=300000000", "--as=150000000", "--as=50000000"};
        for (int k = 0; k < 3; k++) {
            const char *argv[] = {"/usr/bin/prlimit",
                                  limits[k],
                                  ctx->pound,
                                  "simulate",
                                  "--scene",
                                  scene,
                                  "-o",
                                  out,
                                  NULL};
            proc_out r;
            pd_test_spawn(argv, NULL, &r);
            CHECK(ctx, r.status == 1 && strstr(r.err, "memory"),
                  "%s: exit %d, expected 1 and out of memory: %s", limits[k], r.status, r.err);
            CHECK(ctx, pd_test_dir_entries(dir) == 1, "%s: %d files left", limits[k],
                  pd_test_dir_entries(dir) - 1);
            pd_test_proc_free(&r);
        }
    }
    pd_test_rm_dir(dir);
}

/* Defect 2 (generated rows): two SDOFs touching at rest at t = 0 under a
 * cosine pulse (one ground acceleration: zero gap rate and acceleration,
 * a closing jerk) are held from the start, not bounced at t ~ 1e-67 s
 * for ever; the reference agrees with fine Moreau-Jean.  A row whose
 * chatter the reference cannot resolve ends in milliseconds naming the
 * method that runs it, not after its budget of 10^7 events. */
static void test_harden_touching_at_rest_and_chatter(pd_test_ctx *ctx)
{
    const double T0[] = {0.287, 0.112}, xi[] = {0.02, 0.05}, mass[] = {62780.4, 9470914.4};
    const double gap[] = {0.0}, eps[] = {0.869};
    pd_scene *sc = row_of(ctx, 2, T0, xi, mass, gap, eps, 0, PD_PULSE_COSINE, 7.22, 0.24, 0.5);
    pd_scene_result r, m;
    pd_err e;
    if (sc && CHECK(ctx, !pd_scene_result_alloc(sc, &r, &e) && !pd_scene_result_alloc(sc, &m, &e),
                    "%s", e.msg)) {
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        int rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
        CHECK(ctx, rc == PD_OK && r.impacts[0] < 100, "event: %s (%ld impacts)", e.msg,
              r.impacts[0]);
        o.method = PD_METHOD_MOREAU;
        o.dt = 1e-6;
        if (CHECK(ctx, rc == PD_OK && pd_scene_run(sc, &o, NULL, NULL, &m, &e) == PD_OK, "%s",
                  e.msg))
            for (int i = 0; i < 2; i++) /* Moreau-Jean's O(dt) at the impacts: 1e-4 */
                CHECK(ctx, fabs(r.umax[i] - m.umax[i]) <= 1e-4 * m.umax[i],
                      "umax %d: event %.9g, Moreau-Jean %.9g", i, r.umax[i], m.umax[i]);
        pd_scene_result_free(&r);
        pd_scene_result_free(&m);
    }
    pd_scene_free(sc);

    static const double T18[] = {0.301, 0.76,  0.547, 0.124, 0.287, 0.112, 0.583, 0.268, 0.135,
                                 0.734, 0.253, 0.419, 0.175, 0.37,  1.232, 0.342, 0.141, 0.152};
    static const double xi18[] = {0.02, 0.05, 0,    0.05, 0.02, 0.05, 0, 0.05, 0.02,
                                  0.05, 0,    0.02, 0.02, 0.05, 0.05, 0, 0.05, 0.05};
    static const double m18[] = {1036737.4, 157757.7, 10642.3,  3648224.2, 62780.4,   9470914.4,
                                 28070.3,   45986.2,  395486.1, 6343564.5, 8779038.8, 29045.4,
                                 1938422.1, 1610.4,   26957.4,  669901.1,  7169234.3, 47809.5};
    static const double g19[] = {0.05, 0,     0.01, 0.0001, 0.001, 0,     0,    0.01, 0.0001, 0.01,
                                 0,    0.001, 0.05, 0.05,   0.001, 0.001, 0.05, 0.05, 0};
    static const double e19[] = {0.198, 0.385, 0.034, 0.766, 0.454, 0.869, 0.712,
                                 0.855, 0.664, 0.913, 0.304, 0.052, 0.087, 0.078,
                                 0.704, 0.311, 0.36,  0.592, 0.424};
    sc = row_of(ctx, 18, T18, xi18, m18, g19, e19, 1, PD_PULSE_COSINE, 7.22, 0.24, 2.0);
    if (sc && CHECK(ctx, !pd_scene_result_alloc(sc, &r, &e), "%s", e.msg)) {
        pd_run_opts o = pd_run_default_opts();
        o.method = PD_METHOD_EVENT;
        double cpu0 = pd_cpu_seconds();
        int rc = pd_scene_run(sc, &o, NULL, NULL, &r, &e);
        double cpu = pd_cpu_seconds() - cpu0;
        /* an answer, or the chatter named with the method that runs it */
        CHECK(ctx,
              rc == PD_OK || (rc == PD_EBUDGET && strstr(e.msg, "chatter") &&
                              strstr(e.msg, "--method moreau")),
              "rc %d after %.3g s: %s", rc, cpu, e.msg);
        pd_scene_result_free(&r);
    }
    pd_scene_free(sc);
}

/* A status is read back, never guessed, when the caller passes no pd_err:
 * a singular (not diagonal) mass matrix fails the factorisation with
 * PD_ESINGULAR for every engine, err or none (its callers returned
 * PD_ENOMEM without one). */
static void test_harden_status_without_err(pd_test_ctx *ctx)
{
    double M[4] = {1.0, 1.0, 1.0, 1.0}, K[4] = {1.0, 0.0, 0.0, 1.0};
    pd_model md = {.n = 2,
                   .m = 0,
                   .M = pd_matrix_dense(2, 2, M),
                   .C = pd_matrix_zero(2, 2),
                   .K = pd_matrix_dense(2, 2, K),
                   .W = pd_matrix_zero(2, 0)};
    for (int with = 0; with < 2; with++) {
        pd_err e;
        pd_penalty_opts po = pd_penalty_default_opts();
        po.factor = PD_FACTOR_DENSE;
        po.kc = 1e4;
        int rp = pd_penalty_run(&md, 0.0, NULL, NULL, 1.0, &po, NULL, NULL, NULL, with ? &e : NULL);
        pd_edg_opts go = pd_edg_default_opts();
        go.factor = PD_FACTOR_DENSE;
        int rg = pd_edg_run(&md, 0.0, NULL, NULL, 1.0, &go, NULL, NULL, NULL, with ? &e : NULL);
        CHECK(ctx, rp == PD_ESINGULAR && rg == PD_ESINGULAR,
              "%s pd_err: penalty %d, event-general %d, want %d", with ? "with" : "without", rp, rg,
              PD_ESINGULAR);
    }
}

void suite_harden(pd_test_ctx *ctx)
{
    pd_test_run(ctx, "harden_derived_overflow", test_harden_derived_overflow);
    pd_test_run(ctx, "harden_status_without_err", test_harden_status_without_err);
    pd_test_run(ctx, "harden_h5_dimension_names", test_harden_h5_dimension_names);
    pd_test_run(ctx, "harden_cpu_limit_cleans_up", test_harden_cpu_limit_cleans_up);
    pd_test_run(ctx, "harden_bench_shared_and_isa", test_harden_bench_shared_and_isa);
    pd_test_run(ctx, "harden_method_flags", test_harden_method_flags);
    pd_test_run(ctx, "harden_gaps_within_tolerance", test_harden_gaps_within_tolerance);
    pd_test_run(ctx, "harden_memory_limit", test_harden_memory_limit);
    pd_test_run(ctx, "harden_touching_at_rest_and_chatter",
                test_harden_touching_at_rest_and_chatter);
}
